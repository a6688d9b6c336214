// Shell dynamics with known answers: energy conservation in free vibration, the stable-step
// estimate against the true highest frequency, the large-deflection cantilever against the
// elastica, and the clamped plate under pressure against Kirchhoff plate theory.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "test_meshes.hpp"
#include "valvefsi/solid/shell_forces.hpp"
#include "valvefsi/solid/shell_solver.hpp"

namespace valvefsi::solid {
namespace {

using testing::rectangular_plate;

std::vector<std::int64_t> join(const std::vector<std::int64_t>& a, const std::vector<std::int64_t>& b) {
  std::vector<std::int64_t> out = a;
  out.insert(out.end(), b.begin(), b.end());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

// Runs with mass damping until the kinetic energy has decayed; returns the final state.
void relax(ShellSolver& solver, double duration, const Eigen::Matrix3Xd* forces = nullptr) {
  const int chunks = 200;
  const double t0 = solver.state().time;
  for (int k = 1; k <= chunks; ++k) solver.advance_window(t0 + duration * k / chunks, forces);
}

TEST(ShellDynamics, UndampedFreeVibrationConservesEnergy) {
  const Mesh mesh = rectangular_plate(0.02, 0.01, 10, 5, 0.3e-3, true, 0.2);
  ShellModelOptions options;
  options.fixed_nodes = mesh.node_sets.at("left");
  ShellSolver solver(build_shell_model(mesh, options), Material{Ogden{}});
  Eigen::Matrix3Xd v = Eigen::Matrix3Xd::Zero(3, mesh.num_nodes());
  for (Eigen::Index n = 0; n < v.cols(); ++n) {
    const double X = mesh.nodes(0, n) / 0.02;
    v(2, n) = 0.5 * X * X;       // bending
    v(0, n) = 0.05 * X;          // stretching
  }
  solver.set_velocity(v);
  const double initial = 0.5 * (solver.model().nodal_mass.transpose().array() * v.colwise().squaredNorm().array()).sum();
  double max_error = 0;
  for (int k = 1; k <= 100; ++k) {
    solver.advance_window(k * 2e-4);
    const EnergyBalance& e = solver.state().energy;
    max_error = std::max(max_error, std::abs(e.balance()) / initial);
    // The work of the internal forces equals the stored hyperelastic energy.
    EXPECT_NEAR(e.internal_work, e.strain_energy, 2e-3 * initial);
  }
  const EnergyBalance& e = solver.state().energy;
  EXPECT_GT(e.strain_energy, 0.1 * initial) << "the motion must exchange kinetic and strain energy";
  EXPECT_LT(max_error, 2e-3) << "steps: " << solver.state().step;
  EXPECT_EQ(e.damping_work, 0.0);
}

// Largest eigenvalue of M^-1 K at state x by power iteration, K v from finite differences of forces.
double highest_frequency(const ShellModel& model, const Material& material, const Eigen::Matrix3Xd& x) {
  const auto force = [&](const Eigen::Matrix3Xd& y) {
    Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, y.cols());
    std::visit([&](const auto& law) {
      for (const auto& el : model.elements) add_element_internal_force(model, el, law, y, f, false);
    }, material);
    for (Eigen::Index n = 0; n < y.cols(); ++n) {
      if (model.fixed[static_cast<std::size_t>(n)]) f.col(n).setZero();
      f.col(n) /= model.nodal_mass(n);
    }
    return f;
  };
  const Eigen::Matrix3Xd f0 = force(x);
  Eigen::Matrix3Xd v = Eigen::Matrix3Xd::Random(3, x.cols());
  double lambda = 0;
  for (int it = 0; it < 3000; ++it) {
    v /= v.norm();
    const double h = 1e-9;
    const Eigen::Matrix3Xd Kv = (force(x + h * v) - f0) / h;
    lambda = v.cwiseProduct(Kv).sum();
    v = Kv;
  }
  return std::sqrt(lambda);
}

TEST(ShellDynamics, StableStepEstimateIsSafeAndNotWasteful) {
  for (const double thickness : {0.25e-3, 1.0e-3}) {
    const Mesh mesh = rectangular_plate(0.006, 0.004, 6, 4, thickness, true, 0.2);
    ShellModelOptions options;
    options.fixed_nodes = mesh.node_sets.at("left");
    const ShellModel model = build_shell_model(mesh, options);
    for (const double stretch : {1.0, 1.08, -1.08}) {
      // Negative: the stretched plate also rolled onto a cylinder (outer fibres stiffer).
      Eigen::Matrix3Xd x = model.reference_positions;
      x.row(0) *= std::abs(stretch);
      x.row(1) *= std::abs(stretch);
      if (stretch < 0) {
        const double R = 0.004;
        for (Eigen::Index n = 0; n < x.cols(); ++n) {
          const double X = x(0, n);
          x(0, n) = R * std::sin(X / R);
          x(2, n) = R * (1.0 - std::cos(X / R));
        }
      }
      const Material material{Mhgo{}};
      const double exact_step = 2.0 / highest_frequency(model, material, x);
      double estimate = std::numeric_limits<double>::infinity();
      Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, x.cols());
      std::visit([&](const auto& law) {
        for (const auto& el : model.elements)
          estimate = std::min(estimate, add_element_internal_force(model, el, law, x, f, true).stable_step);
      }, material);
      std::printf("stable step: t = %g m, stretch %g: estimate %.4g s, exact %.4g s\n", thickness, stretch,
                  estimate, exact_step);
      EXPECT_LT(estimate, exact_step) << "t = " << thickness << ", stretch " << stretch;
      EXPECT_GT(estimate, 0.3 * exact_step) << "t = " << thickness << ", stretch " << stretch;
    }
  }
}

TEST(ShellDynamics, CantileverMatchesTheElastica) {
  // Tip load P of fixed direction on a clamped strip; Mattiasson's elastica for k = P L^2 / EI.
  const double L = 0.1, b = 0.01, t = 4e-3, E = 1e7;
  const Mesh mesh = rectangular_plate(L, b, 12, 2, t);
  ShellModelOptions options;
  options.fixed_nodes = mesh.node_sets.at("left");
  options.density = 1000.0;
  const ShellModel model = build_shell_model(mesh, options);
  const double EI = E * b * t * t * t / 12.0;
  const double omega1 = 3.516 * std::sqrt(EI / (options.density * b * t * std::pow(L, 4)));
  SolverOptions solver_options;
  solver_options.mass_damping_per_s = 1.5 * omega1;
  struct Case { double k, deflection, shortening; };
  for (const Case c : {Case{1.0, 0.30172, 0.05643}, Case{3.0, 0.60325, 0.25442}}) {
    ShellSolver solver(model, Material{SaintVenantKirchhoff{E, 0.0}}, solver_options);
    const auto& tip = mesh.node_sets.at("right");
    Eigen::Matrix3Xd forces = Eigen::Matrix3Xd::Zero(3, mesh.num_nodes());
    const double P = c.k * EI / (L * L);
    // Consistent load on the tip edge: a quarter at the corners, a half in the middle.
    forces(2, tip[0]) = forces(2, tip[2]) = 0.25 * P;
    forces(2, tip[1]) = 0.5 * P;
    relax(solver, 40.0 / omega1, &forces);
    const Eigen::Matrix3Xd u = solver.displacement();
    EXPECT_NEAR(u(2, tip[1]) / L, c.deflection, 0.03 * c.deflection) << "k = " << c.k;
    EXPECT_NEAR(-u(0, tip[1]) / L, c.shortening, 0.05 * c.shortening) << "k = " << c.k;
    EXPECT_LT(solver.state().energy.kinetic, 1e-6 * solver.state().energy.external_work);
  }
}

TEST(ShellDynamics, ClampedPlateUnderPressureMatchesKirchhoff) {
  // Square plate a x a clamped on all sides, uniform pressure q, small deflection:
  // w_centre = 0.00126 q a^4 / D (Timoshenko & Woinowsky-Krieger, nu = 0.3).
  const double a = 0.02, t = 1e-3, E = 1e7, nu = 0.3;
  const double D = E * t * t * t / (12 * (1 - nu * nu));
  const double q = 0.05 * t * D / (0.00126 * std::pow(a, 4));  // deflection 5 % of the thickness
  const double expected = 0.00126 * q * std::pow(a, 4) / D;
  double previous_error = 1.0;
  for (const int n : {8, 16}) {
    const Mesh mesh = rectangular_plate(a, a, n, n, t);
    ShellModelOptions options;
    options.fixed_nodes = join(join(mesh.node_sets.at("left"), mesh.node_sets.at("right")),
                               join(mesh.node_sets.at("top"), mesh.node_sets.at("bottom")));
    const ShellModel model = build_shell_model(mesh, options);
    const double omega1 = 35.99 / (a * a) * std::sqrt(D / (options.density * t));
    SolverOptions solver_options;
    solver_options.mass_damping_per_s = 1.5 * omega1;
    ShellSolver solver(model, Material{SaintVenantKirchhoff{E, nu}}, solver_options);
    solver.set_pressure([q](double) { return q; });
    relax(solver, 40.0 / omega1);
    const double w = solver.displacement()(2, testing::grid_node(n / 2, n / 2, n));
    const double error = std::abs(w / expected - 1.0);
    std::printf("clamped plate %dx%d: w = %.5g m, Kirchhoff %.5g m, error %.2f %%\n", n, n, w, expected, 100 * error);
    EXPECT_LT(error, 0.35 * previous_error) << "second-order convergence with the mesh";
    previous_error = error;
  }
  EXPECT_LT(previous_error, 0.055);
}

TEST(ShellDynamics, ContactPlaneStopsTheMidSurfaceHalfAThicknessAway) {
  // A pressurised membrane bulges into a rigid plane 0.5 mm above it: the mid-surface stops
  // t/2 below the plane (penalty penetration small), and energy stays balanced.
  const double a = 0.01, t = 0.25e-3, plane_z = 0.5e-3;
  const Mesh mesh = rectangular_plate(a, a, 12, 12, t);
  ShellModelOptions options;
  options.fixed_nodes = join(join(mesh.node_sets.at("left"), mesh.node_sets.at("right")),
                             join(mesh.node_sets.at("top"), mesh.node_sets.at("bottom")));
  options.clamp_fixed_edges = false;
  SolverOptions solver_options;
  solver_options.mass_damping_per_s = 2000.0;
  ShellSolver solver(build_shell_model(mesh, options), Material{NeoHookean{100e3}}, solver_options);
  solver.set_pressure([](double) { return 2000.0; });
  solver.add_contact_plane({Eigen::Vector3d(0, 0, plane_z), Eigen::Vector3d(0, 0, -1)});
  for (int k = 1; k <= 40; ++k) solver.advance_window(k * 1e-3);
  const double top = solver.state().position.row(2).maxCoeff();
  EXPECT_GT(solver.state().nodes_in_contact, 10);
  EXPECT_LT(top, plane_z - 0.5 * t + 0.1 * t) << "penetration beyond 10 % of the thickness";
  EXPECT_GT(top, plane_z - 0.5 * t - 0.02 * t) << "the membrane reaches the contact surface";
  EXPECT_GT(solver.state().energy.contact_work, 0.0);
  EXPECT_LT(solver.state().energy.relative_balance_error(), 1e-2);
}

TEST(ShellDynamics, StentCylinderStopsTheLeafletHalfAThicknessInside) {
  // The same membrane pushed outward (+z) against the inside of a cylinder (axis along x, radius
  // R, its wall 0.5 mm above the plate's centre line): the mid-surface's largest distance from
  // the axis stops at R - t/2 within the penalty tolerance, and the contact work is recorded.
  const double a = 0.01, t = 0.25e-3, R = 0.05, wall_z = 0.5e-3;
  const Mesh mesh = rectangular_plate(a, a, 12, 12, t);
  ShellModelOptions options;
  options.fixed_nodes = join(join(mesh.node_sets.at("left"), mesh.node_sets.at("right")),
                             join(mesh.node_sets.at("top"), mesh.node_sets.at("bottom")));
  options.clamp_fixed_edges = false;
  SolverOptions solver_options;
  solver_options.mass_damping_per_s = 2000.0;
  ShellSolver solver(build_shell_model(mesh, options), Material{NeoHookean{100e3}}, solver_options);
  solver.set_pressure([](double) { return 2000.0; });
  const Eigen::Vector3d origin(0, 0.5 * a, wall_z - R);
  solver.add_contact_cylinder({origin, Eigen::Vector3d::UnitX(), R});
  for (int k = 1; k <= 40; ++k) solver.advance_window(k * 1e-3);
  double farthest = 0;
  const Eigen::Matrix3Xd& x = solver.state().position;
  for (Eigen::Index n = 0; n < x.cols(); ++n) {
    farthest = std::max(farthest, std::hypot(x(1, n) - origin.y(), x(2, n) - origin.z()));
  }
  const double limit = R - 0.5 * t;
  std::printf("stent contact: farthest mid-surface node %.4g t beyond R - t/2, %lld nodes in contact, "
              "contact work %.3g J, balance error %.2e\n", (farthest - limit) / t,
              static_cast<long long>(solver.state().nodes_in_contact), solver.state().energy.contact_work,
              solver.state().energy.relative_balance_error());
  EXPECT_GT(solver.state().nodes_in_contact, 10);
  EXPECT_LT(farthest, limit + 0.1 * t) << "penetration beyond 10 % of the thickness";
  EXPECT_GT(farthest, limit - 0.02 * t) << "the leaflet reaches the stent";
  EXPECT_GT(solver.state().energy.contact_work, 0.0);
  EXPECT_LT(solver.state().energy.relative_balance_error(), 1e-2);
}


TEST(ShellDynamics, TwoLeafletsPressedTogetherStopAThicknessApart) {
  // Two membranes 1 mm apart with normals facing each other; the pressure pushes both toward
  // the other. Their mid-surfaces must stop one thickness apart (t/2 + t/2).
  const double a = 0.01, t = 0.25e-3, spacing = 1e-3;
  Mesh lower = rectangular_plate(a, a, 10, 10, t);
  Mesh mesh = lower;
  const auto n = lower.num_nodes();
  mesh.nodes.conservativeResize(3, 2 * n);
  mesh.nodes.rightCols(n) = lower.nodes;
  mesh.nodes.rightCols(n).row(2).setConstant(spacing);
  mesh.nodes.rightCols(n).row(0) = lower.nodes.row(0) * 1.0;  // same plan view
  for (const auto& tri : lower.triangles) mesh.triangles.push_back({tri[0] + n, tri[2] + n, tri[1] + n});  // normal -z
  mesh.triangle_thickness.assign(mesh.triangles.size(), t);
  mesh.triangle_circumferential = Eigen::Vector3d::UnitX().replicate(1, static_cast<Eigen::Index>(mesh.triangles.size()));
  mesh.triangle_radial = Eigen::Vector3d::UnitY().replicate(1, static_cast<Eigen::Index>(mesh.triangles.size()));
  std::vector<std::int64_t> fixed;
  std::vector<int> surface(static_cast<std::size_t>(2 * n), 0);
  for (const char* side : {"left", "right", "top", "bottom"}) {
    for (const auto i : lower.node_sets.at(side)) {
      fixed.push_back(i);
      fixed.push_back(i + n);
    }
  }
  for (Eigen::Index i = n; i < 2 * n; ++i) surface[static_cast<std::size_t>(i)] = 1;
  ShellModelOptions options;
  options.fixed_nodes = fixed;
  options.clamp_fixed_edges = false;
  SolverOptions solver_options;
  solver_options.mass_damping_per_s = 2000.0;
  ShellSolver solver(build_shell_model(mesh, options), Material{NeoHookean{100e3}}, solver_options);
  solver.set_pressure([](double) { return 2000.0; });
  solver.enable_leaflet_contact(surface);
  for (int k = 1; k <= 40; ++k) solver.advance_window(k * 1e-3);
  const Eigen::Matrix3Xd& x = solver.state().position;
  const auto centre = testing::grid_node(5, 5, 10);
  const double gap = x(2, centre + n) - x(2, centre);
  EXPECT_GT(solver.state().nodes_in_contact, 10);
  EXPECT_GT(gap, 0.9 * t) << "mid-surfaces closer than 90 % of a thickness";
  EXPECT_LT(gap, 1.02 * t) << "the leaflets touch";
  EXPECT_LT(x(2, centre), spacing) << "no crossing";
  // Node-to-triangle penalties are not exactly conservative (closest points switch faces).
  EXPECT_LT(solver.state().energy.relative_balance_error(), 2e-2);
  std::printf("leaflet contact: %lld steps, %lld candidate-list rebuilds, balance error %.2e\n",
              static_cast<long long>(solver.state().step), static_cast<long long>(solver.state().contact_candidates.rebuilds),
              solver.state().energy.relative_balance_error());
  EXPECT_LT(solver.state().contact_candidates.rebuilds, solver.state().step / 2) << "candidate lists are reused";
}

TEST(ShellDynamics, HalfPlateWithASymmetryPlaneMatchesTheFullPlate) {
  // The clamped plate under pressure again, modelled as its half x <= a/2 with a mirror plane:
  // nodes on it keep zero normal displacement and its edge bends as if the other half were there.
  const double a = 0.02, t = 1e-3, E = 1e7, nu = 0.3;
  const double D = E * t * t * t / (12 * (1 - nu * nu));
  const double q = 0.05 * t * D / (0.00126 * std::pow(a, 4));
  const double omega1 = 35.99 / (a * a) * std::sqrt(D / (1100.0 * t));
  SolverOptions solver_options;
  solver_options.mass_damping_per_s = 1.5 * omega1;
  const auto centre_deflection = [&](bool half) {
    const int n = 16;
    const Mesh mesh = rectangular_plate(half ? a / 2 : a, a, half ? n / 2 : n, n, t);
    ShellModelOptions options;
    options.fixed_nodes = join(join(mesh.node_sets.at("left"), half ? std::vector<std::int64_t>{} : mesh.node_sets.at("right")),
                               join(mesh.node_sets.at("top"), mesh.node_sets.at("bottom")));
    const Plane mirror{Eigen::Vector3d(a / 2, 0, 0), Eigen::Vector3d(1, 0, 0)};
    if (half) options.symmetry_planes.push_back(mirror);
    ShellSolver solver(build_shell_model(mesh, options), Material{SaintVenantKirchhoff{E, nu}}, solver_options);
    if (half) {
      std::vector<SymmetryConstraint> on_plane;
      for (const auto i : mesh.node_sets.at("right")) on_plane.push_back({i, mirror.normal});
      solver.add_symmetry_constraints(on_plane);
    }
    solver.set_pressure([q](double) { return q; });
    relax(solver, 40.0 / omega1);
    return solver.displacement()(2, testing::grid_node(n / 2, n / 2, half ? n / 2 : n));
  };
  const double full = centre_deflection(false), half = centre_deflection(true);
  std::printf("plate centre deflection: full %.5g m, half with mirror %.5g m\n", full, half);
  EXPECT_NEAR(half, full, 0.02 * full);
}

}  // namespace
}  // namespace valvefsi::solid
