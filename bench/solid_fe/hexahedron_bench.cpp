// Hexahedron element updates per second (internal force of a loaded plate of bricks), per
// material, with and without the stable-step estimate. One thread.
#include <benchmark/benchmark.h>

#include "hexahedron/hex_test_meshes.hpp"
#include "valvefsi/solid/hexahedron_solver.hpp"

namespace {

using namespace valvefsi::solid;

void hexahedron_internal_force(benchmark::State& state, const SolidMaterial& material) {
  // 32 x 32 bricks, 20 x 20 x 0.25 mm, one through the thickness, like a leaflet.
  const Mesh mesh = testing::box_mesh(0.02, 0.02, 0.25e-3, 32, 32, 1);
  const HexahedronModel model = build_hexahedron_model(mesh, {}, "bench");
  // A loaded state: 8 % biaxial stretch, thinned to keep the volume, and a gentle bulge.
  Eigen::Matrix3Xd x = model.reference_positions;
  for (Eigen::Index n = 0; n < x.cols(); ++n) {
    const double X = x(0, n) - 0.01, Y = x(1, n) - 0.01;
    x(0, n) *= 1.08;
    x(1, n) *= 1.08;
    x(2, n) = x(2, n) / (1.08 * 1.08) - 2.0 * (X * X + Y * Y);
  }
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, x.cols());
  const HexModuli moduli = hex_moduli(shear_modulus(material), bulk_modulus(material));
  const bool estimate = state.range(0) != 0;
  std::visit(
      [&](const auto& law) {
        for (auto _ : state) {
          f.setZero();
          for (const auto& el : model.elements) hex_element_force(el, law, x, 1100.0, moduli, estimate, f);
          benchmark::DoNotOptimize(f.data());
        }
      },
      material);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(model.elements.size()));
}

void BM_HexahedronMhgo(benchmark::State& s) { hexahedron_internal_force(s, SolidMhgo{}); }
void BM_HexahedronOgden(benchmark::State& s) {
  hexahedron_internal_force(s, SolidOgden(OgdenParameters{}, kDefaultTissueBulkModulus_Pa));
}
void BM_HexahedronNeoHookean(benchmark::State& s) {
  hexahedron_internal_force(s, SolidNeoHookean(1e5, kDefaultTissueBulkModulus_Pa));
}
void BM_HexahedronSaintVenantKirchhoff(benchmark::State& s) {
  hexahedron_internal_force(s, SolidSaintVenantKirchhoff(1e6, 0.3));
}

// Argument: 1 = with the stable-step estimate (five extra material evaluations), 0 = forces only.
BENCHMARK(BM_HexahedronMhgo)->Arg(0)->Arg(1);
BENCHMARK(BM_HexahedronOgden)->Arg(0)->Arg(1);
BENCHMARK(BM_HexahedronNeoHookean)->Arg(0)->Arg(1);
BENCHMARK(BM_HexahedronSaintVenantKirchhoff)->Arg(0)->Arg(1);

}  // namespace

BENCHMARK_MAIN();
