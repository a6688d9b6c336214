// The coupled interface of a one-brick-thick leaflet: its mid-surface. Each interface node is a
// ventricular/aortic node pair moving as their mean and taking half of each force, so the force
// and the power the fluid sees equal those the bricks receive.
#include <random>

#include <Eigen/Geometry>

#include <gtest/gtest.h>

#include "hex_test_meshes.hpp"
#include "valvefsi/solid/solid_interface.hpp"

namespace valvefsi::solid {
namespace {

TEST(BrickInterface, MidSurfaceConservesForceAndPower) {
  const double t = 0.25e-3;
  const Mesh mesh = testing::box_mesh(0.01, 0.006, t, 5, 3, 1, 0.0);
  const SolidInterface s = brick_mid_surface_interface(mesh, "box");
  ASSERT_EQ(s.nodes.size(), 24u);                  // (5 + 1) x (3 + 1) pairs
  ASSERT_EQ(s.cells.cols(), 2 * 15);               // two triangles per brick
  EXPECT_NEAR(s.node_areas.sum(), 0.01 * 0.006, 1e-15);
  for (Eigen::Index k = 0; k < s.positions.cols(); ++k) {
    EXPECT_NEAR(s.positions(2, k), 0.5 * t, 1e-15);  // the mid-surface
    EXPECT_NEAR(s.node_thickness(k), t, 1e-15);
  }
  // Triangle normals point to the aortic face (+z here), like the shell's.
  for (Eigen::Index c = 0; c < s.cells.cols(); ++c) {
    const Eigen::Vector3d a = s.positions.col(s.cells(0, c)), b = s.positions.col(s.cells(1, c)),
                          d = s.positions.col(s.cells(2, c));
    EXPECT_GT((b - a).cross(d - a).z(), 0.0);
  }

  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  SolverState state;
  state.position = mesh.nodes;
  state.velocity.resize(3, mesh.num_nodes());
  for (Eigen::Index i = 0; i < state.velocity.size(); ++i) {
    state.position.data()[i] += 1e-4 * u(rng);
    state.velocity.data()[i] = u(rng);
  }
  Eigen::Matrix3Xd interface_forces(3, static_cast<Eigen::Index>(s.nodes.size()));
  for (Eigen::Index i = 0; i < interface_forces.size(); ++i) interface_forces.data()[i] = u(rng);
  Eigen::Matrix3Xd nodal, x, v;
  s.nodal_forces(interface_forces, mesh.num_nodes(), nodal);
  s.motion(state, x, v);
  // Force: the same resultant and moment about the origin (mid-surface points = pair means).
  EXPECT_NEAR((nodal.rowwise().sum() - interface_forces.rowwise().sum()).norm(), 0.0, 1e-12);
  // Power: sum f . v over the interface equals the bricks' nodal power exactly.
  const double interface_power = interface_forces.cwiseProduct(v).sum();
  const double brick_power = nodal.cwiseProduct(state.velocity).sum();
  EXPECT_NEAR(interface_power, brick_power, 1e-12 * std::abs(brick_power));
  // Motion is the pair's mean.
  const auto k = 7;
  EXPECT_NEAR((x.col(k) - 0.5 * (state.position.col(s.nodes[k]) + state.position.col(s.partner[k]))).norm(), 0.0,
              1e-15);
}

TEST(BrickInterface, TwoLayersAreRefusedWithTheElement) {
  const Mesh mesh = testing::box_mesh(0.01, 0.006, 0.5e-3, 2, 2, 2);
  try {
    brick_mid_surface_interface(mesh, "thick.mesh.h5");
    FAIL();
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("thick.mesh.h5: /mesh/hexahedra["), std::string::npos) << what;
    EXPECT_NE(what.find("one brick thick"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace valvefsi::solid
