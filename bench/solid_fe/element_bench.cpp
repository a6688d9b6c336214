// Shell element updates per second (internal force of a loaded plate), per material, with and
// without the stable-step estimate. One thread: multiply by the thread count for the ideal.
#include <vector>

#include <benchmark/benchmark.h>

#include "test_meshes.hpp"
#include "valvefsi/solid/shell_forces.hpp"

namespace {

using namespace valvefsi::solid;

// Argument 1: each triangle computes both hinge sides of its edges (the first sessions' code);
// 2: every triangle's own sides first, then the neighbour's are looked up (each side computed
// once per step, as ShellElements does).
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
  const bool shared_sides = state.range(1) == 2;
  const auto num = static_cast<std::int64_t>(model.elements.size());
  std::vector<HingeSide> sides(static_cast<std::size_t>(3 * num));
  for (auto _ : state) {
    f.setZero();
    if (shared_sides) {
      for (std::int64_t e = 0; e < num; ++e) own_hinge_sides(model, e, x, sides.data());
      for (std::int64_t e = 0; e < num; ++e) {
        add_element_internal_force(model, model.elements[static_cast<std::size_t>(e)], law, x, f, estimate,
                                   sides.data(), e);
      }
    } else {
      for (const auto& el : model.elements) add_element_internal_force(model, el, law, x, f, estimate);
    }
    benchmark::DoNotOptimize(f.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(model.elements.size()));
}

void BM_ShellMhgo(benchmark::State& s) { shell_internal_force(s, Mhgo{}); }
void BM_ShellOgden(benchmark::State& s) { shell_internal_force(s, Ogden{}); }
void BM_ShellNeoHookean(benchmark::State& s) { shell_internal_force(s, NeoHookean{1e5}); }
void BM_ShellSaintVenantKirchhoff(benchmark::State& s) { shell_internal_force(s, SaintVenantKirchhoff{1e6, 0.3}); }

// Arguments: (1 = with the stable-step estimate (tangent at every thickness point), 0 = forces
// only; hinge sides 1 = twice, 2 = once).
BENCHMARK(BM_ShellMhgo)->ArgsProduct({{0, 1}, {1, 2}});
BENCHMARK(BM_ShellOgden)->ArgsProduct({{0, 1}, {1, 2}});
BENCHMARK(BM_ShellNeoHookean)->ArgsProduct({{0, 1}, {1, 2}});
BENCHMARK(BM_ShellSaintVenantKirchhoff)->ArgsProduct({{0, 1}, {1, 2}});

}  // namespace

BENCHMARK_MAIN();
