// 3D proofs with a moving surface (docs/thin-leaflet.md, "3D"):
// (d) a flap attached along its lower edge rocks forward and back in a closed box of water:
//     no leak, nothing lost, water only goes round its free edges;
// (c) a thin disk oscillating normal to itself in a closed box: the in-phase force against
//     the potential-flow added mass (8/3) rho a^3.
// Both run for minutes: validation label only (docs/thin-leaflet.md states what they gave).
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <utility>
#include <vector>

#include "valvefsi/fluid/thin_wall/scenes_3d.hpp"
#include "valvefsi/fluid/thin_wall/solver_run_3d.hpp"


namespace valvefsi::fluid::thin_wall {
namespace {

std::size_t fluid_count(const Particles<3>& p) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < p.size(); ++i) n += p.kind[i] == Kind::fluid ? 1 : 0;
  return n;
}

TEST(ThinWall3DMoving, AttachedFlapRocksWithoutLeaks) {
  omp_set_num_threads(2);
  RockingFlap flap;
  const double dp = 0.01;
  ThinWallSolverRun3D flow(rocking_flap_box(dp, flap));
  const std::size_t start = fluid_count(flow.particles());
  double peak = 0;
  while (flow.time() < flap.period - 1e-9) {
    flow.step();
    peak = std::max(peak, std::abs(flow.wall_force()[0]));
  }
  const auto k = flow.model().counters();
  // Inertia scale of the water the flap pushes: rho b^2 W (tip acceleration theta0 (pi/T)^2 b x 2).
  const double w = std::numbers::pi / flap.period;
  const double scale = 1000.0 * flap.height * flap.height * flap.width * 2.0 * flap.max_angle * w * w * flap.height;
  std::printf("rocking flap (dp %.3f): %zu fluid particles, %ld steps; peak |Fx| %.3f N (inertia scale %.3f N); corrections %zu "
              "leaks %zu rejected shifts %zu lost %zu\n",
              dp, start, flow.step_count(), peak, scale, k.corrections, k.leaks, k.rejected_shifts, flow.solver().lost_count());
  EXPECT_EQ(k.leaks, 0u);
  EXPECT_EQ(flow.solver().lost_count(), 0u);
  EXPECT_EQ(fluid_count(flow.particles()), start);
  EXPECT_LT(peak, 10.0 * scale);  // bounded: no blow-up at the edge
}

// Runs the disk two periods and fits F = alpha w^2 X + beta w V + c over the second; returns
// alpha and beta over the potential-flow added mass (8/3) rho a^3. A quarter disk's force is the
// quarter's: x4.
struct DiskFit {
  double in_phase = 0, velocity_phase = 0;
  std::size_t corrections = 0, leaks = 0;
};
DiskFit fit_disk(const OscillatingDisk& disk, double dp, bool round_edge_state = false) {
  ThinWallCase3D scene = oscillating_disk_box(dp, disk);
  scene.wall_settings.fluid_state_round_free_edge = round_edge_state;
  ThinWallSolverRun3D flow(std::move(scene));
  const double omega = 2.0 * std::numbers::pi / disk.period;
  const double symmetry = disk.quarter ? 4.0 : 1.0;
  std::vector<std::array<double, 4>> rows;
  while (flow.time() < 2.0 * disk.period - 1e-9) {
    flow.step();
    const double t = flow.time();
    if (t < disk.period) continue;
    const double X = -disk.amplitude * std::cos(omega * t), V = disk.amplitude * omega * std::sin(omega * t);
    rows.push_back({omega * omega * X, omega * V, 1.0, symmetry * flow.wall_force()[0]});
  }
  // Least squares by the normal equations (3 x 3).
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (const auto& r : rows) {
    const Eigen::Vector3d a(r[0], r[1], r[2]);
    normal += a * a.transpose();
    rhs += a * r[3];
  }
  const Eigen::Vector3d x = normal.ldlt().solve(rhs);
  const double added = 8.0 / 3.0 * 1000.0 * std::pow(disk.radius, 3);
  // The force of the fluid on the disk opposes its acceleration: F = -m_a a = m_a w^2 X.
  const auto k = flow.model().counters();
  std::printf("oscillating %s disk a/dp = %.1f: in-phase %.4f / potential %.4f = %.3f, velocity-phase %.3f; corrections %zu leaks %zu\n",
              disk.quarter ? "quarter" : "whole", disk.radius / dp, x(0), added, x(0) / added, x(1) / added, k.corrections, k.leaks);
  return {x(0) / added, x(1) / added, k.corrections, k.leaks};
}

TEST(ThinWall3DMoving, OscillatingDiskAgainstPotentialAddedMass) {
  omp_set_num_threads(2);
  OscillatingDisk disk;
  const DiskFit fit = fit_disk(disk, disk.radius / 5);
  EXPECT_EQ(fit.leaks, 0u);
  EXPECT_NEAR(fit.in_phase, 1.0, 0.1);
}

// The same on a quarter of the box with the planes y = 0 and z = 0 (a quarter of the CPU; the
// route to finer disks).
TEST(ThinWall3DMoving, OscillatingQuarterDiskAgainstPotentialAddedMass) {
  omp_set_num_threads(2);
  OscillatingDisk disk;
  disk.quarter = true;
  const DiskFit fit = fit_disk(disk, disk.radius / 5);
  EXPECT_EQ(fit.leaks, 0u);
  EXPECT_NEAR(fit.in_phase, 1.0, 0.1);
}

// The experiment fluid_state_round_free_edge (docs/thin-leaflet.md, session 11): virtual points
// reached round the free edge carry the other side's state. On the quarter disk at a/dp = 5 it
// takes most of the edge's excess away: over T-2T the in-phase coefficient was 1.62 by default
// and 1.10 with the switch (one thread); the potential value in this box with the scene's 20-gon
// rim is 0.985 of (8/3) rho a^3. (It also takes ~40 % of a static pressure jump off a 10 dp
// membrane, thin_wall_3d_model_test, so it stays off.)
TEST(ThinWall3DMoving, RoundEdgeStateTakesMostOfTheQuarterDisksEdgeExcessAway) {
  omp_set_num_threads(2);
  OscillatingDisk disk;
  disk.quarter = true;
  const DiskFit fit = fit_disk(disk, disk.radius / 5, true);
  EXPECT_EQ(fit.leaks, 0u);
  EXPECT_NEAR(fit.in_phase, 1.0, 0.2);  // the default's 1.62 is far outside
}

}  // namespace
}  // namespace valvefsi::fluid::thin_wall
