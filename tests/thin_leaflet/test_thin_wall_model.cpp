// The thin wall behind FluidSolver's immersed-surface hook (2D): chains built from the
// coupler's unordered segments, the window motion (exact for a cubic path), the loads on the
// coupler's nodes equal and opposite to what the walls did to the fluid, the checkpoint, and
// the error messages for bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/fluid/cell_grid.hpp"
#include "valvefsi/fluid/geometry.hpp"
#include "valvefsi/fluid/interactions.hpp"
#include "valvefsi/fluid/thin_wall/thin_wall_model.hpp"

namespace valvefsi::fluid::thin_wall {
namespace {

using Chains = std::vector<std::vector<std::uint32_t>>;

TEST(ThinWallModel, ChainsFromUnorderedSegmentsOfTwoLeaflets) {
  // Leaflet A: nodes 0-1-2-3; leaflet B: 4-5-6; segments shuffled, some reversed.
  const std::vector<std::uint32_t> cells{2, 3, 5, 4, 1, 0, 6, 5, 1, 2};
  EXPECT_EQ(chains_from_segments(7, cells), (Chains{{0, 1, 2, 3}, {4, 5, 6}}));
  // A chain starts at its lowest-numbered end: B numbered from its other end.
  EXPECT_EQ(chains_from_segments(3, std::vector<std::uint32_t>{2, 1, 1, 0}), (Chains{{0, 1, 2}}));
  EXPECT_EQ(chains_from_segments(4, std::vector<std::uint32_t>{3, 1, 1, 2}), (Chains{{2, 1, 3}}));
}

TEST(ThinWallModel, ChainsRefuseBranchesLoopsAndBadIndices) {
  auto message = [](std::size_t n, std::vector<std::uint32_t> cells) {
    try {
      chains_from_segments(n, cells);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(4, {0, 1, 1, 2, 1, 3}).find("node 1 is shared by more than two segments"), std::string::npos);
  EXPECT_NE(message(3, {0, 1, 1, 2, 2, 0}).find("closed loop"), std::string::npos);
  EXPECT_NE(message(3, {0, 1, 1, 7}).find("segment 1 names node 7: allowed 0 to 2"), std::string::npos);
  EXPECT_NE(message(3, {0, 1, 1, 1}).find("segment 1 joins node 1 to itself"), std::string::npos);
  EXPECT_NE(message(3, {0, 1, 1, 0}).find("segments 0 and 1 both join nodes"), std::string::npos);
  EXPECT_NE(message(3, {0, 1, 2}).find("cells has 3 entries"), std::string::npos);
}

// x(t) = x_ref + c2 t^2 + c3 t^3 (at rest at t = 0, as the model starts).
struct CubicPath {
  Vec2 ref, c2, c3;
  Vec2 x(double t) const { return {ref[0] + c2[0] * t * t + c3[0] * t * t * t, ref[1] + c2[1] * t * t + c3[1] * t * t * t}; }
  Vec2 v(double t) const { return {2 * c2[0] * t + 3 * c3[0] * t * t, 2 * c2[1] * t + 3 * c3[1] * t * t}; }
  Vec2 a(double t) const { return {2 * c2[0] + 6 * c3[0] * t, 2 * c2[1] + 6 * c3[1] * t}; }
};

TEST(ThinWallModel, WindowMotionIsExactForACubicPathOverSuccessiveWindows) {
  const std::vector<CubicPath> paths{{{0.0, 0.0}, {0.3, -0.2}, {-1.5, 0.7}}, {{0.01, 0.0}, {-0.4, 0.1}, {2.0, 0.5}}};
  WindowMotion motion({paths[0].ref, paths[1].ref}, 0.0);
  std::vector<Vec2> x, v, a;
  const double T = 0.004;
  for (int window = 0; window < 3; ++window) {
    const double t1 = (window + 1) * T;
    const std::vector<Vec2> x1{paths[0].x(t1), paths[1].x(t1)}, v1{paths[0].v(t1), paths[1].v(t1)};
    motion.set_target(t1, x1, v1);
    for (const double f : {0.0, 0.13, 0.5, 0.77, 1.0}) {
      const double t = window * T + f * T;
      motion.evaluate(t, x, v, a);
      for (std::size_t k = 0; k < 2; ++k)
        for (int d = 0; d < 2; ++d) {
          EXPECT_NEAR(x[k][d], paths[k].x(t)[d], 1e-15);
          EXPECT_NEAR(v[k][d], paths[k].v(t)[d], 1e-12);
          EXPECT_NEAR(a[k][d], paths[k].a(t)[d], 1e-9);
        }
    }
  }
  // Past the last window's end: uniform motion at the end velocity.
  const double end = 3 * T;
  motion.evaluate(end + 0.001, x, v, a);
  EXPECT_NEAR(x[1][0], paths[1].x(end)[0] + 0.001 * paths[1].v(end)[0], 1e-15);
  EXPECT_DOUBLE_EQ(a[1][0], 0.0);
  EXPECT_THROW(motion.set_target(end, std::vector<Vec2>(2), std::vector<Vec2>(2)), std::invalid_argument);
  EXPECT_THROW(motion.set_target(1.0, std::vector<Vec2>(1), std::vector<Vec2>(2)), std::invalid_argument);
}

FluidSettings<2> water(double dp) {
  FluidSettings<2> s;
  s.particle_spacing = dp;
  s.rest_density = 1000.0;
  s.dynamic_viscosity = 1e-3;
  s.sound_speed = 20.0;
  s.artificial_viscosity = 0.02;
  s.gravity = {0.0, -9.81};
  s.domain_lower = {-0.1, -0.1};
  s.domain_upper = {0.1, 0.1};
  return s;
}

// Two leaflets as the solid sends them: a bent one (3 nodes) and a straight one (2 nodes),
// the second's segment given first and reversed.
ImmersedSurfaceGeometry<2> two_leaflets() {
  ImmersedSurfaceGeometry<2> g;
  // Slightly off the particle lattice (no particle exactly on a leaflet).
  g.nodes = {{-0.0301, -0.0199}, {-0.0101, 0.0003}, {-0.0049, 0.0201}, {0.0302, 0.0148}, {0.0099, -0.0152}};
  g.cells = {4, 3, 0, 1, 1, 2};
  g.node_thickness.assign(5, 2.5e-4);
  return g;
}

TEST(ThinWallModel, MoveToPlacesEveryLeafletOnTheWindowsPath) {
  const auto g = two_leaflets();
  ThinWallModel2D model(g, water(0.005), {});
  ASSERT_EQ(model.chains(), (Chains{{0, 1, 2}, {3, 4}}));
  std::vector<CubicPath> paths;
  for (std::size_t k = 0; k < g.nodes.size(); ++k) paths.push_back({g.nodes[k], {0.1 * k, -0.2}, {1.0, 0.3 * k}});
  const double t1 = 0.01;
  std::vector<Vec2> x1, v1;
  for (const auto& p : paths) {
    x1.push_back(p.x(t1));
    v1.push_back(p.v(t1));
  }
  model.set_window_target(t1, x1, v1);
  model.save_checkpoint();
  const double t = 0.0037;
  model.move_to(t);
  const auto& bent = model.walls()[0].wall();
  EXPECT_NEAR(bent.position[2][1], paths[2].x(t)[1], 1e-15);
  EXPECT_NEAR(bent.velocity[1][0], paths[1].v(t)[0], 1e-12);
  EXPECT_NEAR(bent.acceleration[0][1], paths[0].a(t)[1], 1e-9);
  const auto& straight = model.walls()[1].wall();
  EXPECT_NEAR(straight.position[1][0], paths[4].x(t)[0], 1e-15);
  double fastest = 0;
  for (std::size_t k = 0; k < paths.size(); ++k) fastest = std::max(fastest, std::hypot(paths[k].v(t1)[0], paths[k].v(t1)[1]));
  EXPECT_GE(model.max_node_speed(), fastest);
  // Repeating the window (implicit coupling) starts again from the saved state.
  model.move_to(t1);
  model.restore_checkpoint();
  EXPECT_DOUBLE_EQ(model.time(), 0.0);
  EXPECT_DOUBLE_EQ(model.walls()[0].wall().position[2][0], g.nodes[2][0]);
  model.move_to(t);
  EXPECT_NEAR(model.walls()[0].wall().position[2][1], paths[2].x(t)[1], 1e-15);
}

TEST(ThinWallModel, NodeForcesAreMinusWhatTheWallsDidToTheFluid) {
  const double dp = 0.005;
  const auto s = water(dp);
  SceneGeometry<2> scene;
  scene.fluid.push_back({{-0.05, -0.05}, {0.05, 0.05}, {}, [](const Vec<2>&) { return 0.0; }});
  Particles<2> p = fill_particles<2>(scene, s);
  // A lively field: random velocities and density excesses (so pressures and both sides'
  // states differ), so every term of the virtual layers contributes.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.velocity[0][i] = 0.2f * u(rng);
    p.velocity[1][i] = 0.2f * u(rng);
    p.viscous_velocity[0][i] = p.velocity[0][i];
    p.viscous_velocity[1][i] = p.velocity[1][i];
    p.density_excess[i] = 2.0f * u(rng);
  }
  CellGrid<2> grid(s.domain_lower, s.domain_upper, s.support_radius(), s.periodic);
  grid.wrap_and_mark_lost(p);
  grid.sort(p);
  ThinWallModel2D model(two_leaflets(), s, {});
  // The leaflets move through the window, so the wall state includes their acceleration.
  const auto g = two_leaflets();
  std::vector<Vec2> x1 = g.nodes, v1(g.nodes.size(), Vec2{0.05, -0.02});
  for (auto& x : x1) x[0] += 1e-4;
  model.set_window_target(0.002, x1, v1);
  model.begin_step(p);
  model.move_to(0.001);
  model.correct_crossings(p);
  grid.sort(p);
  model.classify(p);
  update_fluid_pressure<2>(p, s);
  model.update_surface_states(p, grid);
  for (int d = 0; d < 2; ++d) std::fill(p.acceleration[d].begin(), p.acceleration[d].end(), 0.0f);
  model.add_surface_rates(p);
  double on_fluid[2] = {0, 0}, scale = 0;
  std::size_t near = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.kind[i] != Kind::fluid) continue;
    near += model.near_surface(i) ? 1 : 0;
    for (int d = 0; d < 2; ++d) {
      on_fluid[d] += s.particle_mass() * p.acceleration[d][i];
      scale += s.particle_mass() * std::abs(p.acceleration[d][i]);
    }
  }
  std::vector<Vec<2>> f(model.node_count());
  model.node_forces(f);
  double on_nodes[2] = {0, 0};
  for (const auto& fk : f)
    for (int d = 0; d < 2; ++d) on_nodes[d] += fk[d];
  std::printf("node forces sum (%.6g, %.6g) N/m, on the fluid (%.6g, %.6g) N/m, %zu near-wall particles\n", on_nodes[0],
              on_nodes[1], on_fluid[0], on_fluid[1], near);
  EXPECT_GT(near, 100u);
  ASSERT_GT(scale, 0.0);
  for (int d = 0; d < 2; ++d) EXPECT_NEAR(on_nodes[d], -on_fluid[d], 1e-6 * scale);
  // Non-trivial: the fluid's pressure (about 40 Pa per kg/m^3 of excess) pushes on the leaflets.
  EXPECT_GT(std::hypot(on_nodes[0], on_nodes[1]), 1e-3);
  EXPECT_EQ(model.counters().leaks, 0u);
}

TEST(ThinWallModel, BlockedAcrossEitherLeafletAndNotAround) {
  const double dp = 0.005;
  const auto s = water(dp);
  SceneGeometry<2> scene;
  scene.fluid.push_back({{-0.05, -0.05}, {0.05, 0.05}, {}, [](const Vec<2>&) { return 0.0; }});
  Particles<2> p = fill_particles<2>(scene, s);
  CellGrid<2> grid(s.domain_lower, s.domain_upper, s.support_radius(), s.periodic);
  grid.sort(p);
  ThinWallModel2D model(two_leaflets(), s, {});
  model.classify(p);
  auto find = [&](double x, double y) {
    for (std::uint32_t i = 0; i < p.size(); ++i)
      if (std::abs(p.position[0][i] - x) < 1e-9 && std::abs(p.position[1][i] - y) < 1e-9) return i;
    ADD_FAILURE() << "no particle at " << x << ", " << y;
    return 0u;
  };
  // Across the straight leaflet (it passes y = 0.0025 at x = 0.0219).
  EXPECT_TRUE(model.blocked(find(0.0175, 0.0025), find(0.0225, 0.0025), p));
  // Across the bent one's first segment (y = -0.0199 + 1.01 (x + 0.0301)).
  EXPECT_TRUE(model.blocked(find(-0.0225, -0.0075), find(-0.0175, -0.0125), p));
  // Beside the first leaflet, on one side.
  EXPECT_FALSE(model.blocked(find(-0.0225, -0.0175), find(-0.0175, -0.0175), p));
}

TEST(ThinWallModel, FactoryChecksTheGeometryAndTheCasePart) {
  const auto s = water(0.005);
  cases::FluidThinWalls part;
  EXPECT_NE(make_thin_wall_model_2d(two_leaflets(), s, part), nullptr);
  auto g = two_leaflets();
  g.node_thickness.pop_back();
  try {
    make_thin_wall_model_2d(g, s, part);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("node_thickness has 4 entries: allowed one per node (5)"), std::string::npos) << e.what();
  }
  g = two_leaflets();
  g.nodes_per_cell = 3;
  EXPECT_THROW(make_thin_wall_model_2d(g, s, part), std::invalid_argument);
  part.set_virtual_spacing_ratio(2.0);
  try {
    make_thin_wall_model_2d(two_leaflets(), s, part);
    ADD_FAILURE() << "no error";
  } catch (const CaseError& e) {
    EXPECT_NE(std::string(e.what()).find("virtual_spacing_ratio"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace valvefsi::fluid::thin_wall
