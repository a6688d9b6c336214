// Brick dynamics with known answers: cantilever convergence to beam theory, no volumetric
// locking at nu = 0.4999, energy balance of a free vibration, the stable step against the
// measured instability limit, save/restore.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "../test_meshes.hpp"
#include "hex_test_meshes.hpp"
#include "valvefsi/solid/hexahedron_solver.hpp"
#include "valvefsi/solid/shell_solver.hpp"

namespace valvefsi::solid {
namespace {

using testing::box_mesh;

constexpr double kLength = 0.01, kThickness = 0.001, kWidth = 0.001;

struct Cantilever {
  Mesh mesh;
  std::unique_ptr<HexahedronSolver> solver;
};

// Beam along x clamped at x = 0, one brick through the thickness (z) and the width (y).
Cantilever cantilever(int elements, SolidMaterial material, double damping, bool plane_strain) {
  Cantilever c;
  c.mesh = box_mesh(kLength, kWidth, kThickness, elements, 1, 1);
  HexahedronSolverOptions options;
  options.mass_damping_per_s = damping;
  c.solver = std::make_unique<HexahedronSolver>(
      build_hexahedron_model(c.mesh, {1100.0, c.mesh.node_sets.at("x0")}, "cantilever"), std::move(material), options);
  if (plane_strain) {
    std::vector<SymmetryConstraint> all;
    for (Eigen::Index n = 0; n < c.mesh.nodes.cols(); ++n) all.push_back({n, Eigen::Vector3d::UnitY()});
    c.solver->add_symmetry_constraints(all);
  }
  return c;
}

// Static tip deflection under a tip load P (down, -z) by damped dynamics.
double tip_deflection(Cantilever& c, double load, double end_time) {
  Eigen::Matrix3Xd forces = Eigen::Matrix3Xd::Zero(3, c.mesh.nodes.cols());
  const auto& tip = c.mesh.node_sets.at("x1");
  for (const auto n : tip) forces(2, n) = -load / static_cast<double>(tip.size());
  c.solver->advance_window(end_time, &forces);
  double w = 0;
  for (const auto n : tip) w += c.solver->displacement()(2, n);
  return -w / static_cast<double>(tip.size());
}

// Timoshenko cantilever: PL^3 / (3 E I) + P L / (5/6 G A).
double beam_deflection(double load, double E, double G) {
  const double I = kWidth * std::pow(kThickness, 3) / 12.0, A = kWidth * kThickness;
  return load * std::pow(kLength, 3) / (3.0 * E * I) + load * kLength / (5.0 / 6.0 * G * A);
}

TEST(HexahedronCantilever, ConvergesToBeamTheory) {
  // Saint Venant-Kirchhoff with nu = 0 (plane stress = plane strain), E = 1 MPa; deflection ~1 % of L.
  const double E = 1e6, load = 2.5e-5;
  const double expected = beam_deflection(load, E, E / 2.0);
  std::vector<double> errors;
  for (const int n : {5, 10, 20}) {
    Cantilever c = cantilever(n, SolidSaintVenantKirchhoff(E, 0.0), 600.0, false);
    const double w = tip_deflection(c, load, 0.08);
    errors.push_back(w / expected - 1.0);
    std::printf("cantilever %2d x 1 x 1 bricks: tip %.5g mm, beam %.5g mm, error %+.2f %%, hourglass/strain %.3f\n",
                n, w * 1e3, expected * 1e3, 100 * errors.back(),
                c.solver->state().energy.hourglass_energy / c.solver->state().energy.strain_energy);
    EXPECT_LT(c.solver->state().velocity.norm(), 1e-3 * w / 0.01);  // at rest
  }
  EXPECT_LT(std::abs(errors[2]), 0.02);
  EXPECT_LT(std::abs(errors[2]), std::abs(errors[0]));
}

TEST(HexahedronCantilever, NearlyIncompressiblePlaneStrainDoesNotLock) {
  // nu = 0.4999 (kappa = 5000 mu), plane strain: E' = 2 mu / (1 - nu), shear modulus mu.
  // A fully integrated trilinear brick locks here (tip deflection a small fraction of this).
  const double mu = 1e5, kappa = 5000.0 * mu, load = 1e-5;
  const double nu = (3 * kappa - 2 * mu) / (2 * (3 * kappa + mu));
  const double expected = beam_deflection(load, 2 * mu / (1 - nu), mu);
  Cantilever c = cantilever(10, SolidNeoHookean(mu, kappa), 400.0, true);
  const double w = tip_deflection(c, load, 0.06);
  std::printf("nu = %.4f plane-strain cantilever 10 bricks: tip %.5g mm, beam %.5g mm, error %+.2f %%\n", nu, w * 1e3,
              expected * 1e3, 100 * (w / expected - 1));
  EXPECT_NEAR(w / expected, 1.0, 0.04);
}

TEST(HexahedronPlate, ClampedSquarePlateUnderPressureConvergesToKirchhoff) {
  // Quarter of a clamped 10 x 10 mm plate, t = 0.25 mm (a/t = 40), one brick through the thickness,
  // SVK E = 1 MPa, nu = 0.3; uniform pressure on the lower faces; centre deflection against
  // Kirchhoff's 0.00126 q a^4 / D (deflection 5 % of t: linear). Needs the Poisson coupling of the
  // bending modes and the exact twist (without them the plate was 13 % too flexible at any mesh).
  const double a = 0.01, t = 0.25e-3, E = 1e6, nu = 0.3;
  const double D = E * t * t * t / (12 * (1 - nu * nu));
  const double q = 0.05 * t * D / (0.00126 * std::pow(a, 4));
  std::vector<double> errors;
  for (const int n : {4, 8}) {
    const Mesh mesh = box_mesh(a / 2, a / 2, t, n, n, 1);
    std::vector<std::int64_t> clamped = mesh.node_sets.at("x0");
    clamped.insert(clamped.end(), mesh.node_sets.at("y0").begin(), mesh.node_sets.at("y0").end());
    HexahedronSolverOptions options;
    options.mass_damping_per_s = 1200.0;
    HexahedronSolver solver(build_hexahedron_model(mesh, {1100.0, clamped}, "plate"), SolidSaintVenantKirchhoff(E, nu),
                            options);
    std::vector<SymmetryConstraint> mirror;
    for (const auto i : mesh.node_sets.at("x1")) mirror.push_back({i, Eigen::Vector3d::UnitX()});
    for (const auto i : mesh.node_sets.at("y1")) mirror.push_back({i, Eigen::Vector3d::UnitY()});
    solver.add_symmetry_constraints(mirror);
    solver.set_pressure([q](double) { return q; }, ventricular_faces(mesh));
    solver.advance_window(0.03);
    double w = 0;
    for (const auto i : mesh.node_sets.at("x1")) {
      if (std::abs(mesh.nodes(1, i) - a / 2) < 1e-12) w += 0.5 * solver.displacement()(2, i);
    }
    const double expected = 0.00126 * q * std::pow(a, 4) / D;
    errors.push_back(w / expected - 1);
    std::printf("clamped plate %2d x %2d bricks (full plate): centre %.5g um, Kirchhoff %.5g um, error %+.2f %%\n",
                2 * n, 2 * n, w * 1e6, expected * 1e6, 100 * errors.back());
  }
  // Kirchhoff neglects transverse shear, which adds ~2 % at a/t = 40: the bricks converge to just above it.
  EXPECT_LT(std::abs(errors[0]), 0.03);
  EXPECT_LT(std::abs(errors[1]), 0.03);
  EXPECT_LT(std::abs(errors[1] - errors[0]), 0.015);
}

TEST(HexahedronPlate, ShellAndBricksAgreeOnALargeDeflectionPlate) {
  // The same clamped 10 x 10 mm plate, t = 0.25 mm, SVK E = 1 MPa, nu = 0.3, under 40x the load
  // above: centre deflection ~2 t, membrane action. Shell: full plate, 16 x 16 x 2 triangles;
  // bricks: quarter of the 16 x 16 plate. Independent element families, same physics.
  const double a = 0.01, t = 0.25e-3, E = 1e6, nu = 0.3;
  const double D = E * t * t * t / (12 * (1 - nu * nu));
  const double q = 40 * 0.05 * t * D / (0.00126 * std::pow(a, 4));

  const Mesh bricks = box_mesh(a / 2, a / 2, t, 8, 8, 1);
  std::vector<std::int64_t> clamped = bricks.node_sets.at("x0");
  clamped.insert(clamped.end(), bricks.node_sets.at("y0").begin(), bricks.node_sets.at("y0").end());
  HexahedronSolverOptions hex_options;
  hex_options.mass_damping_per_s = 1200.0;
  HexahedronSolver hex(build_hexahedron_model(bricks, {1100.0, clamped}, "plate"), SolidSaintVenantKirchhoff(E, nu),
                       hex_options);
  std::vector<SymmetryConstraint> mirror;
  for (const auto i : bricks.node_sets.at("x1")) mirror.push_back({i, Eigen::Vector3d::UnitX()});
  for (const auto i : bricks.node_sets.at("y1")) mirror.push_back({i, Eigen::Vector3d::UnitY()});
  hex.add_symmetry_constraints(mirror);
  hex.set_pressure([q](double) { return q; }, ventricular_faces(bricks));
  hex.advance_window(0.03);
  double w_hex = 0;
  for (const auto i : bricks.node_sets.at("x1")) {
    if (std::abs(bricks.nodes(1, i) - a / 2) < 1e-12) w_hex += 0.5 * hex.displacement()(2, i);
  }

  const Mesh sheet = testing::rectangular_plate(a, a, 16, 16, t);
  ShellModelOptions shell_options;
  for (const char* edge : {"left", "right", "top", "bottom"}) {
    const auto& nodes = sheet.node_sets.at(edge);
    shell_options.fixed_nodes.insert(shell_options.fixed_nodes.end(), nodes.begin(), nodes.end());
  }
  SolverOptions solver_options;
  solver_options.mass_damping_per_s = 1200.0;
  ShellSolver shell(build_shell_model(sheet, shell_options), SaintVenantKirchhoff(E, nu), solver_options);
  shell.set_pressure([q](double) { return q; });
  shell.advance_window(0.03);
  const double w_shell = shell.displacement()(2, testing::grid_node(8, 8, 16));

  std::printf("large-deflection plate: centre %.4f mm (bricks) vs %.4f mm (shell): %+.2f %%; linear Kirchhoff %.4f mm\n",
              w_hex * 1e3, w_shell * 1e3, 100 * (w_hex / w_shell - 1), 40 * 0.05 * t * 1e3);
  EXPECT_GT(w_shell, t);                        // large deflection: membrane action
  EXPECT_LT(w_shell, 0.8 * 40 * 0.05 * t);      // well below the linear answer
  EXPECT_NEAR(w_hex / w_shell, 1.0, 0.05);
}

TEST(HexahedronLocking, NearlyIncompressibleThickCylinderUnderPressure) {
  // Lame: quarter of a thick cylinder a = 5 mm, b = 10 mm in plane strain, internal pressure p,
  // neo-Hookean kappa = 5000 mu (nu = 0.4999): u_r(a) = p a^2 / (2 mu (b^2 - a^2)) [(1 - 2 nu) a + b^2 / a].
  // The classic volumetric-locking case (fully integrated bricks give a fraction of it).
  const double a = 0.005, b = 0.01, mu = 1e5, kappa = 5000 * mu, p = 10.0;
  const double nu = (3 * kappa - 2 * mu) / (2 * (3 * kappa + mu));
  const int nr = 8, nt = 8;
  Mesh mesh = box_mesh(b - a, M_PI / 2, 0.5e-3, nr, nt, 1);
  for (Eigen::Index n = 0; n < mesh.nodes.cols(); ++n) {
    const double r = a + mesh.nodes(0, n), theta = mesh.nodes(1, n);
    mesh.nodes.col(n) = Eigen::Vector3d(r * std::cos(theta), r * std::sin(theta), mesh.nodes(2, n));
  }
  HexahedronSolverOptions options;
  options.mass_damping_per_s = 3000.0;
  HexahedronSolver solver(build_hexahedron_model(mesh, {1100.0, {}}, "cylinder"), SolidNeoHookean(mu, kappa), options);
  std::vector<SymmetryConstraint> constraints;
  for (Eigen::Index n = 0; n < mesh.nodes.cols(); ++n) constraints.push_back({n, Eigen::Vector3d::UnitZ()});
  for (const auto n : mesh.node_sets.at("y0")) constraints.push_back({n, Eigen::Vector3d::UnitY()});
  for (const auto n : mesh.node_sets.at("y1")) constraints.push_back({n, Eigen::Vector3d::UnitX()});
  solver.add_symmetry_constraints(constraints);
  // Inner faces (box face x = 0), ordered so that their normal points into the wall (+r).
  std::vector<PressureFace> inner;
  for (int j = 0; j < nt; ++j) {
    inner.push_back({testing::box_node(0, j, 0, nr, nt), testing::box_node(0, j + 1, 0, nr, nt),
                     testing::box_node(0, j + 1, 1, nr, nt), testing::box_node(0, j, 1, nr, nt)});
  }
  solver.set_pressure([p](double) { return p; }, inner);
  solver.advance_window(0.008);
  double u = 0;
  for (const auto n : mesh.node_sets.at("x0")) u += solver.displacement().col(n).head<2>().norm();
  u /= static_cast<double>(mesh.node_sets.at("x0").size());
  const double expected = p * a * a / (2 * mu * (b * b - a * a)) * ((1 - 2 * nu) * a + b * b / a);
  std::printf("thick cylinder, nu = %.4f, %d x %d bricks: u_r(a) %.5g um, Lame %.5g um, error %+.2f %%\n", nu, nr, nt,
              u * 1e6, expected * 1e6, 100 * (u / expected - 1));
  EXPECT_NEAR(u / expected, 1.0, 0.03);
}

TEST(HexahedronDynamics, UndampedFreeVibrationConservesEnergy) {
  // MHGO cantilever (reference Table 1, kappa = 2/D) released with a bending velocity field.
  Cantilever c = cantilever(10, SolidMhgo(), 0.0, false);
  Eigen::Matrix3Xd v = Eigen::Matrix3Xd::Zero(3, c.mesh.nodes.cols());
  for (Eigen::Index n = 0; n < v.cols(); ++n) v(2, n) = 0.5 * std::pow(c.mesh.nodes(0, n) / kLength, 2);
  c.solver->set_velocity(v);
  double largest_error = 0;
  for (int window = 1; window <= 20; ++window) {
    c.solver->advance_window(window * 5e-4);
    largest_error = std::max(largest_error, c.solver->state().energy.relative_balance_error());
  }
  const auto& e = c.solver->state().energy;
  std::printf("free vibration 10 ms, %lld steps: balance error %.2e (largest %.2e), KE %.3e J, strain %.3e J, "
              "hourglass energy %.3e J (work %.3e J), internal work %.3e J\n",
              static_cast<long long>(c.solver->state().step), e.relative_balance_error(), largest_error, e.kinetic,
              e.strain_energy, e.hourglass_energy, e.hourglass_work, e.internal_work);
  EXPECT_LT(largest_error, 1e-2);
  EXPECT_NEAR(e.internal_work, e.strain_energy + e.hourglass_energy, 1e-2 * e.initial_kinetic);
  EXPECT_GT(e.hourglass_energy, 0.0);  // one brick through the thickness bends through its hourglass modes
}

TEST(HexahedronDynamics, StableStepEstimateIsBelowTheMeasuredLimit) {
  // Free, distorted block with random velocities: run 3000 steps at dt = f x the estimated critical
  // step; the estimate (f = 1) must be stable, and the first unstable f tells how conservative it is.
  for (const double kappa : {1e6, 1e8}) {
    const Mesh mesh = box_mesh(0.004, 0.002, 0.001, 4, 2, 2, 0.3);
    std::mt19937 rng(1);
    std::normal_distribution<double> g(0.0, 1e-3);
    Eigen::Matrix3Xd v = Eigen::Matrix3Xd::NullaryExpr(3, mesh.nodes.cols(), [&] { return g(rng); });
    const auto unstable = [&](double factor) {
      HexahedronSolver solver(build_hexahedron_model(mesh, {1100.0, {}}, "block"), SolidNeoHookean(1e5, kappa));
      solver.set_step_factor_for_testing(factor);
      solver.set_velocity(v);
      solver.advance_window(0.0);
      const double dt = solver.state().stable_step;
      solver.advance_window(3000 * dt);
      return !(solver.state().energy.kinetic < 1e3 * solver.state().energy.initial_kinetic);
    };
    EXPECT_FALSE(unstable(1.0)) << "kappa " << kappa;
    double limit = 0;
    for (double f = 1.05; f < 4.0; f += 0.05) {
      bool blew_up = false;
      try {
        blew_up = unstable(f);
      } catch (const MaterialStateError&) {
        blew_up = true;
      }
      if (blew_up) {
        limit = f;
        break;
      }
    }
    std::printf("kappa/mu = %g: instability at %.2f x the estimated critical step\n", kappa / 1e5, limit);
    EXPECT_GT(limit, 1.0);
    EXPECT_LT(limit, 3.0);
  }
}

TEST(HexahedronDynamics, RestoreReplaysTheSameSteps) {
  Cantilever c = cantilever(5, SolidOgden(OgdenParameters{}, 2e7), 0.0, false);
  Eigen::Matrix3Xd forces = Eigen::Matrix3Xd::Zero(3, c.mesh.nodes.cols());
  for (const auto n : c.mesh.node_sets.at("x1")) forces(2, n) = -1e-4;
  c.solver->advance_window(1e-3, &forces);
  const HexahedronState saved = c.solver->state();
  c.solver->advance_window(2e-3, &forces);
  const Eigen::Matrix3Xd first = c.solver->state().position;
  c.solver->restore(saved);
  c.solver->advance_window(2e-3, &forces);
  EXPECT_EQ((c.solver->state().position - first).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_DOUBLE_EQ(c.solver->state().time, 2e-3);
}

}  // namespace
}  // namespace valvefsi::solid
