// 2D plane-strain strips (docs/solid_fe.md, "2D strip mode"): a one-element-deep strip with tied
// front/back nodes and u_z = 0 bends like a plane-strain beam, D = E t^3 / (12 (1 - nu^2)), or
// 4 mu t^3 / 12 when incompressible; the ties hold to round-off.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "test_meshes.hpp"
#include "valvefsi/solid/neo_hookean.hpp"
#include "valvefsi/solid/saint_venant_kirchhoff.hpp"
#include "valvefsi/solid/shell_solver.hpp"

namespace valvefsi::solid::testing {
namespace {

constexpr double kLength = 0.01, kThickness = 0.5e-3, kDepth = 1e-3, kPressure = 0.1;

struct StripResult {
  double deflection;        // y of the monitored front node
  double tie_error;         // largest |x_front - x_back| in x-y
  double largest_z_motion;  // largest |u_z|
};

std::vector<StripTie> ties_of(const Mesh& mesh) {
  std::vector<StripTie> ties;
  for (std::size_t k = 0; k < mesh.node_sets.at("strip_front").size(); ++k) {
    ties.push_back({mesh.node_sets.at("strip_front")[k], mesh.node_sets.at("strip_back")[k]});
  }
  return ties;
}

// Static deflection under a small uniform pressure, reached with near-critical mass damping.
StripResult static_strip(Material material, bool clamp_both_ends, double omega_estimate) {
  const int segments = 20;
  const Mesh mesh = strip_mesh({straight_polyline({0, 0}, {1, 0}, kLength, segments)}, kDepth, kThickness);
  ShellModelOptions options;
  options.fixed_nodes = mesh.node_sets.at("attachment");
  if (clamp_both_ends) {
    for (const auto n : mesh.node_sets.at("free_edge")) options.fixed_nodes.push_back(n);
  }
  SolverOptions solver_options;
  solver_options.mass_damping_per_s = 2.0 * omega_estimate;
  ShellSolver solver(build_shell_model(mesh, options), std::move(material), solver_options);
  solver.set_strip_ties(ties_of(mesh));
  solver.set_pressure([](double) { return kPressure; });
  solver.advance_window(15.0 / omega_estimate);
  const std::int64_t probe = clamp_both_ends ? segments / 2 : segments;  // front node: midpoint or tip
  StripResult r{solver.displacement()(1, probe), 0.0, solver.displacement().row(2).cwiseAbs().maxCoeff()};
  for (const auto& t : ties_of(mesh)) {
    r.tie_error = std::max(r.tie_error, (solver.state().position.col(t.front) - solver.state().position.col(t.back))
                                            .head<2>().norm());
  }
  return r;
}

double plane_strain_rigidity(double modulus) { return modulus * std::pow(kThickness, 3) / 12.0; }

TEST(SolidStrip, CantileverMatchesPlaneStrainBeamTheory) {
  const double E = 1e6, nu = 0.3;
  const double D = plane_strain_rigidity(E / (1 - nu * nu));
  const double omega = 3.516 * std::sqrt(D / (1100 * kThickness)) / (kLength * kLength);
  const StripResult r = static_strip(SaintVenantKirchhoff(E, nu), false, omega);
  const double expected = kPressure * std::pow(kLength, 4) / (8 * D);  // towards +y = z x e_x
  EXPECT_NEAR(r.deflection, expected, 0.02 * expected) << "tip " << r.deflection << " m, beam " << expected << " m";
  EXPECT_LT(r.tie_error, 1e-12 * kLength);
  EXPECT_EQ(r.largest_z_motion, 0.0);
  std::printf("cantilever strip: tip %.6g m, beam %.6g m (%+.2f %%), tie error %.2g m\n", r.deflection, expected,
              100 * (r.deflection / expected - 1), r.tie_error);
}

TEST(SolidStrip, IncompressibleCantileverHasTheFourThirdsFactor) {
  const double mu = 3e5;
  const double D = plane_strain_rigidity(4 * mu);  // E / (1 - nu^2) = 3 mu / (3/4)
  const double omega = 3.516 * std::sqrt(D / (1100 * kThickness)) / (kLength * kLength);
  const StripResult r = static_strip(NeoHookean(mu), false, omega);
  const double expected = kPressure * std::pow(kLength, 4) / (8 * D);
  EXPECT_NEAR(r.deflection, expected, 0.02 * expected) << "tip " << r.deflection << " m, beam " << expected << " m";
  EXPECT_LT(r.tie_error, 1e-12 * kLength);
  std::printf("incompressible strip: tip %.6g m, beam %.6g m (%+.2f %%)\n", r.deflection, expected,
              100 * (r.deflection / expected - 1));
}

TEST(SolidStrip, ClampedClampedMatchesPlaneStrainBeamTheory) {
  const double E = 1e6, nu = 0.3;
  const double D = plane_strain_rigidity(E / (1 - nu * nu));
  const double omega = 22.37 * std::sqrt(D / (1100 * kThickness)) / (kLength * kLength);
  const StripResult r = static_strip(SaintVenantKirchhoff(E, nu), true, omega);
  const double expected = kPressure * std::pow(kLength, 4) / (384 * D);
  EXPECT_NEAR(r.deflection, expected, 0.03 * expected) << "mid " << r.deflection << " m, beam " << expected << " m";
  EXPECT_LT(r.tie_error, 1e-12 * kLength);
  std::printf("clamped-clamped strip: mid %.6g m, beam %.6g m (%+.2f %%)\n", r.deflection, expected,
              100 * (r.deflection / expected - 1));
}

}  // namespace
}  // namespace valvefsi::solid::testing
