// Shell triangle: fold-angle gradients, internal force = gradient of the strain energy,
// rigid-body invariance, membrane and bending patch tests.
#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "test_meshes.hpp"
#include "valvefsi/solid/hinge_angle.hpp"
#include "valvefsi/solid/shell_forces.hpp"
#include "valvefsi/solid/shell_elements.hpp"
#include "valvefsi/solid/shell_solver.hpp"

#include <omp.h>

namespace valvefsi::solid {
namespace {

using testing::rectangular_plate;

TEST(HingeAngle, GradientMatchesFiniteDifferences) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (int trial = 0; trial < 20; ++trial) {
    std::array<Eigen::Vector3d, 4> x{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                                     Eigen::Vector3d(0.5, 1, 0), Eigen::Vector3d(0.4, -1, 0)};
    for (auto& p : x) p += Eigen::Vector3d(u(rng), u(rng), u(rng));
    const auto angle = [&](const std::array<Eigen::Vector3d, 4>& y) {
      return fold_angle(hinge_side(y[0], y[1], y[2], false), hinge_side(y[0], y[1], y[3], true), y[0], y[1]);
    };
    const HingeSide a = hinge_side(x[0], x[1], x[2], false), b = hinge_side(x[0], x[1], x[3], true);
    const std::array<Eigen::Vector3d, 4> grad{a.grad_start + b.grad_start, a.grad_end + b.grad_end,
                                              a.grad_opposite, b.grad_opposite};
    for (int n = 0; n < 4; ++n) {
      for (int d = 0; d < 3; ++d) {
        auto xp = x, xm = x;
        xp[n](d) += 1e-6;
        xm[n](d) -= 1e-6;
        EXPECT_NEAR((angle(xp) - angle(xm)) / 2e-6, grad[n](d), 1e-6) << "node " << n << " dir " << d;
      }
    }
    // Clamped: rotation of side A against its own reference normal.
    const Eigen::Vector3d n0 = a.unit_normal;
    auto y = x;
    y[2] += 0.05 * n0;
    const HingeSide moved = hinge_side(y[0], y[1], y[2], false);
    for (int d = 0; d < 3; ++d) {
      auto yp = y, ym = y;
      yp[2](d) += 1e-6;
      ym[2](d) -= 1e-6;
      const double fd = (clamped_angle(hinge_side(yp[0], yp[1], yp[2], false), n0, yp[0], yp[1]) -
                         clamped_angle(hinge_side(ym[0], ym[1], ym[2], false), n0, ym[0], ym[1])) / 2e-6;
      EXPECT_NEAR(fd, moved.grad_opposite(d), 1e-6);
    }
  }
}

double total_strain_energy(const ShellModel& model, const Material& material, const Eigen::Matrix3Xd& x,
                           Eigen::Matrix3Xd* forces = nullptr) {
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, x.cols());
  double energy = 0;
  std::visit([&](const auto& law) {
    for (const auto& el : model.elements) energy += add_element_internal_force(model, el, law, x, f, false).strain_energy;
  }, material);
  if (forces != nullptr) *forces = f;
  return energy;
}

TEST(ShellElement, InternalForceIsTheGradientOfTheStrainEnergy) {
  const Mesh mesh = rectangular_plate(0.01, 0.006, 4, 3, 0.4e-3, true, 0.2);
  ShellModelOptions options;
  options.fixed_nodes = mesh.node_sets.at("left");  // clamped edge on the left
  options.symmetry_planes.push_back({Eigen::Vector3d(0.01, 0, 0), Eigen::Vector3d(1, 0, 0)});  // mirror on the right
  const ShellModel model = build_shell_model(mesh, options);
  ASSERT_TRUE(std::any_of(model.elements.begin(), model.elements.end(), [](const ShellElement& el) {
    return std::count(el.edge_kind.begin(), el.edge_kind.end(), EdgeKind::mirror) > 0;
  }));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const Material& material : {Material{Ogden{}}, Material{Mhgo{}}, Material{NeoHookean{1e5}},
                                   Material{SaintVenantKirchhoff{1e6, 0.3}}}) {
    // A bent and stretched state: out-of-plane bulge plus a few per cent random in-plane strain.
    Eigen::Matrix3Xd x = model.reference_positions;
    for (Eigen::Index n = 0; n < x.cols(); ++n) {
      const double X = x(0, n), Y = x(1, n);
      x(0, n) *= 1.04;
      x(1, n) *= 1.02;
      x(2, n) = 0.08 * X * X / 0.01 + 0.02 * X * Y / 0.01;
      x.col(n) += 0.01 * 0.006 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    }
    Eigen::Matrix3Xd f;
    total_strain_energy(model, material, x, &f);
    const double scale = f.cwiseAbs().maxCoeff();
    ASSERT_GT(scale, 0.0);
    for (Eigen::Index n = 0; n < x.cols(); ++n) {
      if (model.fixed[static_cast<std::size_t>(n)]) continue;  // reactions; these nodes never move
      for (int d = 0; d < 3; ++d) {
        const double h = 1e-9;
        Eigen::Matrix3Xd xp = x, xm = x;
        xp(d, n) += h;
        xm(d, n) -= h;
        const double fd = (total_strain_energy(model, material, xp) - total_strain_energy(model, material, xm)) / (2 * h);
        EXPECT_NEAR(fd, f(d, n), 1e-5 * scale) << material_name(material) << " node " << n << " dir " << d;
      }
    }
    // The solver's path computes each hinge side once and shares it with the neighbour: the same
    // forces and energy to round-off.
    ShellElements shared(model, material);
    Eigen::Matrix3Xd g;
    const InternalForceResult r = shared.internal_force(x, false, g, nullptr);
    EXPECT_LT((g - f).cwiseAbs().maxCoeff(), 1e-12 * scale) << material_name(material);
    EXPECT_NEAR(r.strain_energy, total_strain_energy(model, material, x), 1e-12 * std::abs(r.strain_energy));
  }
}

TEST(ShellElement, RigidMotionGivesNoForce) {
  const Mesh mesh = rectangular_plate(0.01, 0.01, 4, 4, 0.3e-3, false, 0.25);
  const ShellModel model = build_shell_model(mesh, {});
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Matrix3Xd x = (R * model.reference_positions).colwise() + Eigen::Vector3d(0.3, -0.1, 0.2);
  Eigen::Matrix3Xd f;
  const double energy = total_strain_energy(model, Material{Mhgo{}}, x, &f);
  EXPECT_NEAR(energy, 0.0, 1e-15);
  EXPECT_LT(f.cwiseAbs().maxCoeff(), 1e-9);
}

TEST(ShellElement, MembranePatchTestOnAnIrregularMesh) {
  // Homogeneous in-plane stretch: every element carries the same stress, interior nodes are in
  // equilibrium, and the right edge carries the traction sigma * thickness * height.
  const double lx = 0.02, ly = 0.01, t = 0.5e-3;
  const Mesh mesh = rectangular_plate(lx, ly, 6, 4, t, true, 0.3);
  const ShellModel model = build_shell_model(mesh, {});
  const SaintVenantKirchhoff svk(2e6, 0.3);
  const double stretch = 1.05;
  Eigen::Matrix3Xd x = model.reference_positions;
  x.row(0) *= stretch;
  Eigen::Matrix3Xd f;
  total_strain_energy(model, Material{svk}, x, &f);
  const double E11 = 0.5 * (stretch * stretch - 1.0);
  const double S11 = svk.youngs_modulus() / (1 - 0.09) * E11;  // plane stress, E22 = 0 (held)
  const double edge_force = stretch * S11 * t * ly;            // first Piola-Kirchhoff P11 = F11 S11
  double right = 0;
  for (const auto n : mesh.node_sets.at("right")) right += f(0, n);
  EXPECT_NEAR(right, edge_force, 1e-9 * edge_force);
  for (Eigen::Index n = 0; n < x.cols(); ++n) {
    const double X = mesh.nodes(0, n), Y = mesh.nodes(1, n);
    const bool boundary = X < 1e-12 || X > lx - 1e-12 || Y < 1e-12 || Y > ly - 1e-12;
    if (!boundary) {
      EXPECT_LT(f.col(n).norm(), 1e-9 * edge_force) << "interior node " << n;
    }
  }
}

TEST(ShellElement, BendingPatchTestRecoversCylinderCurvature) {
  // Roll a plate onto a cylinder of radius R about the y-axis: interior elements must report
  // kappa11 = 1/R and no other curvature, on an irregular mesh.
  const double lx = 0.01, ly = 0.01, R = 0.02;
  const Mesh mesh = rectangular_plate(lx, ly, 10, 10, 0.2e-3, true, 0.2);
  const ShellModel model = build_shell_model(mesh, {});
  Eigen::Matrix3Xd x = model.reference_positions;
  for (Eigen::Index n = 0; n < x.cols(); ++n) {
    const double X = mesh.nodes(0, n);
    x(0, n) = R * std::sin(X / R);
    x(2, n) = R * (1.0 - std::cos(X / R));
  }
  int checked = 0;
  for (const auto& el : model.elements) {
    if (std::any_of(el.edge_kind.begin(), el.edge_kind.end(), [](EdgeKind k) { return k != EdgeKind::interior; })) continue;
    const ElementState s = element_kinematics(model, el, x);
    EXPECT_NEAR(s.curvature(0, 0), 1.0 / R, 0.03 / R);
    EXPECT_NEAR(s.curvature(1, 1), 0.0, 0.03 / R);
    EXPECT_NEAR(s.curvature(0, 1), 0.0, 0.03 / R);
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

TEST(ShellElement, ThreadedForcesEqualSerialForces) {
  // Large enough for the threaded path: per-thread accumulation must give the serial sum.
  const Mesh mesh = rectangular_plate(0.02, 0.02, 24, 24, 0.25e-3, false, 0.2);
  const ShellModel model = build_shell_model(mesh, {});
  ASSERT_GE(model.elements.size(), 1000u);
  Eigen::Matrix3Xd v = Eigen::Matrix3Xd::Zero(3, mesh.num_nodes());
  for (Eigen::Index n = 0; n < v.cols(); ++n) v(2, n) = std::sin(300.0 * mesh.nodes(0, n)) * mesh.nodes(1, n);
  std::array<Eigen::Matrix3Xd, 2> forces;
  const int saved = omp_get_max_threads();
  for (int threads = 1; threads <= 2; ++threads) {
    omp_set_num_threads(threads);
    ShellSolver solver(model, Material{Mhgo{}});
    solver.set_velocity(v);
    solver.advance_window(2e-5);
    forces[threads - 1] = solver.state().internal_force;
  }
  omp_set_num_threads(saved);
  EXPECT_LT((forces[0] - forces[1]).cwiseAbs().maxCoeff(), 1e-10 * forces[0].cwiseAbs().maxCoeff());
  EXPECT_GT(forces[0].cwiseAbs().maxCoeff(), 0.0);
}

}  // namespace
}  // namespace valvefsi::solid
