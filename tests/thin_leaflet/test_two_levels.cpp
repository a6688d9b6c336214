// 2D proofs (a) and (b) of the thin wall (docs/thin-leaflet.md):
// (a) a thin wall buried in the floor between water levels 1.0 m and 0.5 m holds both levels
//     with no leak, and the fluid's net force on it is rho g (h1^2 - h2^2) / 2; the same with
//     the wall's end flush on the floor (attachment line);
// (b) the same wall standing 0.1 m above the floor: water flows under its free end, the run
//     stays stable for 3 s, the levels equalise towards (h1 + h2) / 2, no leak.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "valvefsi/fluid/thin_wall/scenes_2d.hpp"
#include "valvefsi/fluid/thin_wall/solver_run_2d.hpp"

namespace valvefsi::fluid::thin_wall {
namespace {

struct Levels {
  double left = 0, right = 0;
  std::size_t left_count = 0, right_count = 0;
};

// Water level on each side: the fluid area over the width (particles times dp^2 / 0.5 m).
Levels levels(const ThinWallSolverRun2D& flow) {
  const auto& p = flow.particles();
  const double dp = flow.settings().particle_spacing;
  Levels l;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.kind[i] != Kind::fluid) continue;
    if (p.position[0][i] < 0.5) ++l.left_count;
    else ++l.right_count;
  }
  l.left = static_cast<double>(l.left_count) * dp * dp / 0.5;
  l.right = static_cast<double>(l.right_count) * dp * dp / 0.5;
  return l;
}

// Highest fluid particle on each side, plus dp/2 (the free surface).
Levels surface(const ThinWallSolverRun2D& flow) {
  const auto& p = flow.particles();
  const double dp = flow.settings().particle_spacing;
  Levels l;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.kind[i] != Kind::fluid) continue;
    double& top = p.position[0][i] < 0.5 ? l.left : l.right;
    top = std::max(top, p.position[1][i] + dp / 2);
  }
  return l;
}

// The scenes hold ~2000 particles: one thread, since threading overhead exceeds the work.
// The closed wall with its lower (attached) end at height `bottom` (< 0: buried in the floor).
void closed_wall(double bottom, const char* name) {
  omp_set_num_threads(1);
  const double dp = 0.025, h1 = 1.0, h2 = 0.5, rho = 1000.0, g = 9.81;
  ThinWallCase2D c = two_level_tank(dp, h1, h2, 0.0);
  c.walls.front().position.front()[1] = bottom;
  ThinWallSolverRun2D flow(std::move(c));
  const Levels start = levels(flow);
  flow.advance_to(0.5);
  double fx = 0, fy = 0;
  int samples = 0;
  while (flow.time() < 1.0 - 1e-9) {
    flow.step();
    fx += flow.wall_force()[0];
    fy += flow.wall_force()[1];
    ++samples;
  }
  fx /= samples;
  fy /= samples;
  const double expected = rho * g * (h1 * h1 - h2 * h2) / 2;
  const Levels end = levels(flow);
  const Levels top = surface(flow);
  std::printf("closed wall, %s: force %.1f N/m (analytic %.1f, %+.2f %%), vertical %.2f N/m; surface %.4f / %.4f m; "
              "corrections %zu leaks %zu\n",
              name, fx, expected, 100 * (fx / expected - 1), fy, top.left, top.right, flow.wall_model().counters().corrections,
              flow.wall_model().counters().leaks);
  EXPECT_NEAR(fx, expected, 0.02 * expected);
  EXPECT_EQ(end.left_count, start.left_count);
  EXPECT_EQ(end.right_count, start.right_count);
  EXPECT_NEAR(top.left, h1, dp);
  EXPECT_NEAR(top.right, h2, dp);
  EXPECT_EQ(flow.wall_model().counters().leaks, 0u);
  EXPECT_EQ(flow.lost_count(), 0u);
}

TEST(ThinWallTwoLevels, ClosedWallHoldsLevelsAndCarriesTheHydrostaticLoad) { closed_wall(-0.075, "buried 3 dp"); }

// The attachment line: the leaflet's end exactly on the rigid floor (the solid's attached end
// on the stent wall), no burial: the corner must not let water under the wall.
TEST(ThinWallTwoLevels, WallAttachedFlushOnTheFloorHoldsLevels) { closed_wall(0.0, "attached flush on the floor"); }

TEST(ThinWallTwoLevels, GapUnderTheFreeEndEqualisesLevelsStablyWithoutLeaks) {
  omp_set_num_threads(1);
  const double dp = 0.025, h1 = 1.0, h2 = 0.5;
  auto scene = two_level_tank(dp, h1, h2, 0.1);
  scene.fluid.shifting = 1.0;  // keeps the particles regular in the fast flow round the edge
  ThinWallSolverRun2D flow(std::move(scene));
  const std::size_t fluid = levels(flow).left_count + levels(flow).right_count;
  double max_speed = 0, difference = 0;
  int samples = 0;
  while (flow.time() < 3.0 - 1e-9) {
    flow.step();
    const auto& p = flow.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.kind[i] == Kind::fluid) max_speed = std::max(max_speed, std::hypot(double(p.velocity[0][i]), double(p.velocity[1][i])));
    if (flow.time() > 2.5) {
      const Levels l = levels(flow);
      difference += l.left - l.right;
      ++samples;
    }
  }
  difference /= samples;
  const Levels end = levels(flow);
  std::printf("gap: after 3 s levels %.4f / %.4f m (mean difference over 2.5-3 s %.4f m), max speed %.2f m/s "
              "(Torricelli %.2f), corrections %zu leaks %zu rejected shifts %zu\n",
              end.left, end.right, difference, max_speed, std::sqrt(2 * 9.81 * (h1 - h2)),
              flow.wall_model().counters().corrections, flow.wall_model().counters().leaks,
              flow.wall_model().counters().rejected_shifts);
  // Stable: no particle faster than the free-fall speed from the higher level.
  EXPECT_LT(max_speed, std::sqrt(2 * 9.81 * h1));
  // Equalised: the initial difference of 0.5 m is down to a tenth.
  EXPECT_LT(std::abs(difference), 0.05);
  EXPECT_NEAR(end.left + end.right, h1 + h2, 1e-9);
  EXPECT_EQ(end.left_count + end.right_count, fluid);
  EXPECT_EQ(flow.wall_model().counters().leaks, 0u);
  EXPECT_EQ(flow.lost_count(), 0u);
}

}  // namespace
}  // namespace valvefsi::fluid::thin_wall
