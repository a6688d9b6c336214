// Shell element updates per second (internal force of a loaded plate), per material, with and
// without the stable-step estimate. One thread: multiply by the thread count for the ideal.
#include <benchmark/benchmark.h>

#include "test_meshes.hpp"
#include "valvefsi/solid/shell_forces.hpp"

namespace {

using namespace valvefsi::solid;

template <class Law>
void shell_internal_force(benchmark::State& state, Law law) {
  const Mesh mesh = testing::rectangular_plate(0.02, 0.02, 32, 32, 0.25e-3, false, 0.2);
  const ShellModel model = build_shell_model(mesh, {});
  // A loaded state: 8 % biaxial stretch and a gentle bulge, like an open leaflet.
  Eigen::Matrix3Xd x = model.reference_positions * 1.08;
  for (Eigen::Index n = 0; n < x.cols(); ++n) {
    const double X = x(0, n) - 0.01, Y = x(1, n) - 0.01;
    x(2, n) = -2.0 * (X * X + Y * Y);
  }
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, x.cols());
  const bool estimate = state.range(0) != 0;
  for (auto _ : state) {
    f.setZero();
    for (const auto& el : model.elements) add_element_internal_force(model, el, law, x, f, estimate);
    benchmark::DoNotOptimize(f.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(model.elements.size()));
}

void BM_ShellMhgo(benchmark::State& s) { shell_internal_force(s, Mhgo{}); }
void BM_ShellOgden(benchmark::State& s) { shell_internal_force(s, Ogden{}); }
void BM_ShellNeoHookean(benchmark::State& s) { shell_internal_force(s, NeoHookean{1e5}); }
void BM_ShellSaintVenantKirchhoff(benchmark::State& s) { shell_internal_force(s, SaintVenantKirchhoff{1e6, 0.3}); }

// Argument: 1 = with the stable-step estimate (tangent at every thickness point), 0 = forces only.
BENCHMARK(BM_ShellMhgo)->Arg(0)->Arg(1);
BENCHMARK(BM_ShellOgden)->Arg(0)->Arg(1);
BENCHMARK(BM_ShellNeoHookean)->Arg(0)->Arg(1);
BENCHMARK(BM_ShellSaintVenantKirchhoff)->Arg(0)->Arg(1);

}  // namespace

BENCHMARK_MAIN();
