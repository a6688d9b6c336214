// The coaptation bridge of the 2D thin wall (docs/thin-leaflet.md, "Coaptation bridge"): two
// free ends of different leaflets within the coaptation distance are joined, for the fluid, by
// a two-sided wall. Unit checks of the model (engage, release with hysteresis, pairs blocked
// across the gap, loads onto the two ends, checkpoint and restart state) and the physical
// proof: the two-level tank whose dividing wall is split by a gap of 0.4 dp drains through the
// gap without the bridge and holds both levels, with the hydrostatic load, with it.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/fluid/cell_grid.hpp"
#include "valvefsi/fluid/geometry.hpp"
#include "valvefsi/fluid/interactions.hpp"
#include "valvefsi/fluid/thin_wall/scenes_2d.hpp"
#include "valvefsi/fluid/thin_wall/solver_run_2d.hpp"
#include "valvefsi/fluid/thin_wall/thin_wall_model.hpp"

namespace valvefsi::fluid::thin_wall {
namespace {

FluidSettings<2> still_water(double dp) {
  FluidSettings<2> s;
  s.particle_spacing = dp;
  s.rest_density = 1000.0;
  s.dynamic_viscosity = 1e-3;
  s.sound_speed = 20.0;
  s.domain_lower = {-0.1, -0.1};
  s.domain_upper = {0.1, 0.1};
  return s;
}

// A closed 2D valve's section: two leaflets along y = 0.0001 from the walls at x = -/+0.03 m,
// their tips `gap` apart about x = 0 (each chain numbered from its attached end).
ImmersedSurfaceGeometry<2> two_tips(double gap) {
  ImmersedSurfaceGeometry<2> g;
  g.nodes = {{-0.03, 1e-4}, {-0.015, 1e-4}, {-gap / 2, 1e-4}, {0.03, 1e-4}, {gap / 2, 1e-4}};
  g.cells = {0, 1, 1, 2, 3, 4};
  g.node_thickness.assign(5, 2.5e-4);
  return g;
}

Particles<2> box_of_water(const FluidSettings<2>& s, CellGrid<2>& grid) {
  SceneGeometry<2> scene;
  scene.fluid.push_back({{-0.05, -0.05}, {0.05, 0.05}, {}, [](const Vec<2>&) { return 0.0; }});
  Particles<2> p = fill_particles<2>(scene, s);
  grid.sort(p);
  return p;
}

std::uint32_t particle_at(const Particles<2>& p, double x, double y) {
  for (std::uint32_t i = 0; i < p.size(); ++i)
    if (std::abs(p.position[0][i] - x) < 1e-9 && std::abs(p.position[1][i] - y) < 1e-9) return i;
  ADD_FAILURE() << "no particle at " << x << ", " << y;
  return 0;
}

// Moves the model's nodes to `nodes` over one window and steps it once (begin_step engages or
// releases the bridges from the distance at the step's start).
void window_to(ThinWallModel2D& model, Particles<2>& p, CellGrid<2>& grid, double t, const std::vector<Vec2>& nodes) {
  model.set_window_target(t, nodes, std::vector<Vec2>(nodes.size(), Vec2{0.0, 0.0}));
  model.move_to(t);
  model.begin_step(p);
  model.correct_crossings(p);
  grid.sort(p);
  model.classify(p);
}

TEST(CoaptationBridge, EngagesBelowTheDistanceReleasesAboveItsMultipleAndBlocksTheGap) {
  const double dp = 0.005;
  const auto s = still_water(dp);
  CellGrid<2> grid(s.domain_lower, s.domain_upper, s.support_radius(), s.periodic);
  Particles<2> p = box_of_water(s, grid);
  auto g = two_tips(0.006);
  ThinWallModel2D model(g, s, {}, 0.008);
  // Four end pairs can be bridged (each end of the first chain with each of the second's).
  ASSERT_EQ(model.bridges().size(), 4u);
  model.begin_step(p);
  model.classify(p);
  auto engaged = [&] {
    std::size_t n = 0;
    for (const auto& b : model.bridges()) n += b.wall ? 1 : 0;
    return n;
  };
  // Only the tips (nodes 2 and 4, 6 mm apart) engaged; the attached ends are 60 mm apart.
  ASSERT_EQ(engaged(), 1u);
  const auto& bridge = *std::find_if(model.bridges().begin(), model.bridges().end(), [](const auto& b) { return b.wall.has_value(); });
  EXPECT_EQ(bridge.node_a, 2u);
  EXPECT_EQ(bridge.node_b, 4u);
  // Particles straddling the gap at x = -dp/2 (the lattice sits at odd multiples of dp/2, the
  // tips at -/+3 mm) do not interact; without the bridge they would.
  const auto above = particle_at(p, -0.0025, 0.0025), below = particle_at(p, -0.0025, -0.0025);
  EXPECT_TRUE(model.blocked(above, below, p));
  ThinWallModel2D open_model(g, s, {}, 0.0);
  open_model.classify(p);
  EXPECT_TRUE(open_model.bridges().empty());
  EXPECT_TRUE(open_model.blocked(particle_at(p, -0.0075, 0.0025), particle_at(p, -0.0075, -0.0025), p));
  EXPECT_FALSE(open_model.blocked(above, below, p));

  // Hysteresis: 9.5 mm apart (between 8 and 10 mm) stays engaged, 10.5 mm releases, 9.5 mm
  // again does not re-engage, 7.5 mm does.
  auto tips_apart = [&](double d) {
    auto x = g.nodes;
    x[2][0] = -d / 2;
    x[4][0] = d / 2;
    return x;
  };
  window_to(model, p, grid, 1e-3, tips_apart(0.0095));
  EXPECT_EQ(engaged(), 1u);
  window_to(model, p, grid, 2e-3, tips_apart(0.0105));
  EXPECT_EQ(engaged(), 0u);
  window_to(model, p, grid, 3e-3, tips_apart(0.0095));
  EXPECT_EQ(engaged(), 0u);
  window_to(model, p, grid, 4e-3, tips_apart(0.0075));
  EXPECT_EQ(engaged(), 1u);
  EXPECT_EQ(model.bridge_engagements(), 2u);
  // The engaged bridge follows the tips.
  const auto& w = std::find_if(model.bridges().begin(), model.bridges().end(), [](const auto& b) { return b.wall.has_value(); })->wall->wall();
  EXPECT_DOUBLE_EQ(w.position[0][0], -0.00375);
  EXPECT_DOUBLE_EQ(w.position[1][0], 0.00375);
  // A checkpoint restores the bridge's state (implicit coupling repeats a window).
  model.save_checkpoint();
  window_to(model, p, grid, 5e-3, tips_apart(0.012));
  EXPECT_EQ(engaged(), 0u);
  model.restore_checkpoint();
  EXPECT_EQ(engaged(), 1u);
  EXPECT_EQ(model.bridge_engagements(), 2u);
}

TEST(CoaptationBridge, NodeForcesIncludeTheBridgeAndAreMinusWhatTheWallsDidToTheFluid) {
  const double dp = 0.005;
  auto s = still_water(dp);
  CellGrid<2> grid(s.domain_lower, s.domain_upper, s.support_radius(), s.periodic);
  Particles<2> p = box_of_water(s, grid);
  // Higher pressure above the leaflets than below: the bridge carries its share.
  for (std::size_t i = 0; i < p.size(); ++i) p.density_excess[i] = p.position[1][i] > 0.0 ? 2.0f : 0.0f;
  ThinWallModel2D model(two_tips(0.006), s, {}, 0.008);
  model.begin_step(p);
  model.classify(p);
  update_fluid_pressure<2>(p, s);
  model.update_surface_states(p, grid);
  for (int d = 0; d < 2; ++d) std::fill(p.acceleration[d].begin(), p.acceleration[d].end(), 0.0f);
  model.add_surface_rates(p);
  double on_fluid[2] = {0, 0}, scale = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int d = 0; d < 2; ++d) {
      on_fluid[d] += s.particle_mass() * p.acceleration[d][i];
      scale += s.particle_mass() * std::abs(p.acceleration[d][i]);
    }
  std::vector<Vec<2>> f(model.node_count());
  model.node_forces(f);
  double on_nodes[2] = {0, 0};
  for (const auto& fk : f)
    for (int d = 0; d < 2; ++d) on_nodes[d] += fk[d];
  const auto& bridge = *std::find_if(model.bridges().begin(), model.bridges().end(), [](const auto& b) { return b.wall.has_value(); });
  const Vec2 on_bridge = bridge.wall->markers().total_force();
  std::printf("node forces (%.5g, %.5g) N/m, on the fluid (%.5g, %.5g) N/m, on the bridge (%.5g, %.5g) N/m\n", on_nodes[0],
              on_nodes[1], on_fluid[0], on_fluid[1], on_bridge[0], on_bridge[1]);
  for (int d = 0; d < 2; ++d) EXPECT_NEAR(on_nodes[d], -on_fluid[d], 1e-6 * scale);
  // The pressure above (about 40 Pa per kg/m^3 of excess) pushes the bridge down, and its load
  // reaches the tips: a 6 mm bridge under ~80 Pa carries of the order of 0.5 N/m.
  EXPECT_LT(on_bridge[1], -0.1);
  EXPECT_LT(f[2][1] + f[4][1], on_bridge[1] * 0.5);
}

TEST(CoaptationBridge, RestartStateRoundTripsAndOldStateLoadsWithBridgesReleased) {
  const double dp = 0.005;
  const auto s = still_water(dp);
  CellGrid<2> grid(s.domain_lower, s.domain_upper, s.support_radius(), s.periodic);
  Particles<2> p = box_of_water(s, grid);
  const auto g = two_tips(0.006);
  ThinWallModel2D model(g, s, {}, 0.008);
  model.begin_step(p);
  model.classify(p);
  const auto state = model.restart_state();
  ASSERT_TRUE(state.has_value());
  ThinWallModel2D again(g, s, {}, 0.008);
  again.load_restart_state(*state);
  const auto state2 = again.restart_state();
  ASSERT_EQ(state2->size(), state->size());
  for (std::size_t k = 0; k < state->size(); ++k) {
    EXPECT_EQ((*state2)[k].name, (*state)[k].name);
    EXPECT_EQ((*state2)[k].values, (*state)[k].values) << (*state)[k].name;
  }
  // A restart written without coaptation: the bridges start released and engage at the next step.
  ThinWallModel2D without(g, s, {}, 0.0);
  without.begin_step(p);
  without.classify(p);
  ThinWallModel2D later(g, s, {}, 0.008);
  later.load_restart_state(*without.restart_state());
  for (const auto& b : later.bridges()) EXPECT_FALSE(b.wall.has_value());
  later.begin_step(p);
  std::size_t engaged = 0;
  for (const auto& b : later.bridges()) engaged += b.wall ? 1 : 0;
  EXPECT_EQ(engaged, 1u);
}

TEST(CoaptationBridge, FactoryReadsTheDistanceAndRefusesANegativeOne) {
  const auto s = still_water(0.005);
  cases::FluidThinWalls part;
  part.set_coaptation_distance(0.008);
  auto model = make_thin_wall_model_2d(two_tips(0.006), s, part);
  EXPECT_DOUBLE_EQ(dynamic_cast<ThinWallModel2D&>(*model).coaptation_distance(), 0.008);
  part.set_coaptation_distance(-1e-3);
  try {
    make_thin_wall_model_2d(two_tips(0.006), s, part);
    ADD_FAILURE() << "no error";
  } catch (const CaseError& e) {
    EXPECT_NE(std::string(e.what()).find("coaptation_distance"), std::string::npos) << e.what();
  }
}

struct TankResult {
  std::size_t left_start = 0, left_end = 0, leaks = 0, lost = 0;
  double force = 0.0;  // mean horizontal force on all nodes over 0.5-1 s (N/m)
};

// The two-level tank (h1 = 1 m, h2 = 0.5 m, dp = 0.025 m) with its wall split at y = 0.25 m by
// a gap of 0.4 dp, run for 1 s.
TankResult split_tank(double coaptation_distance) {
  omp_set_num_threads(1);
  const double dp = 0.025;
  ThinWallCase2D c = two_level_tank_with_joint(dp, 1.0, 0.5, 0.25, 0.4 * dp);
  c.coaptation_distance = coaptation_distance;
  ThinWallSolverRun2D flow(std::move(c));
  auto left = [&] {
    std::size_t n = 0;
    const auto& p = flow.particles();
    for (std::size_t i = 0; i < p.size(); ++i) n += p.kind[i] == Kind::fluid && p.position[0][i] < 0.5 ? 1 : 0;
    return n;
  };
  TankResult r;
  r.left_start = left();
  flow.advance_to(0.5);
  int samples = 0;
  std::vector<Vec<2>> f(flow.model().node_count());
  while (flow.time() < 1.0 - 1e-9) {
    flow.step();
    flow.model().node_forces(f);
    for (const auto& fk : f) r.force += fk[0];
    ++samples;
  }
  r.force /= samples;
  r.left_end = left();
  r.leaks = flow.model().counters().leaks;
  r.lost = flow.lost_count();
  return r;
}

TEST(CoaptationBridge, SplitWallDrainsThroughTheGapWithoutTheBridgeAndHoldsWithIt) {
  const double expected = 1000.0 * 9.81 * (1.0 * 1.0 - 0.5 * 0.5) / 2;
  const TankResult open = split_tank(0.0);
  const TankResult joined = split_tank(0.6 * 0.025);
  std::printf("split wall, gap 0.4 dp: without the bridge %zu -> %zu particles on the left, force %.1f N/m; with it %zu -> %zu, "
              "force %.1f N/m (analytic %.1f, %+.2f %%), leaks %zu, lost %zu\n",
              open.left_start, open.left_end, open.force, joined.left_start, joined.left_end, joined.force, expected,
              100 * (joined.force / expected - 1), joined.leaks, joined.lost);
  // Without the bridge the higher side drains through the 1 cm gap: the orifice law (C_d 0.6,
  // 3.1 m/s under 0.5 m of head) moves 0.019 m^2/s, 30 particles a second (16 measured,
  // start-up included).
  EXPECT_GE(open.left_start, open.left_end + 8);
  // With it not one particle changes side, and the whole wall carries the hydrostatic load.
  EXPECT_EQ(joined.left_end, joined.left_start);
  EXPECT_NEAR(joined.force, expected, 0.02 * expected);
  EXPECT_EQ(joined.leaks, 0u);
  EXPECT_EQ(joined.lost, 0u);
}

}  // namespace
}  // namespace valvefsi::fluid::thin_wall
