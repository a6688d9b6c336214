// 2D dam break (water column 1 m wide, 2 m high, tank 4 m) against the surge-front positions
// measured by Martin & Moyce (1952), data in data/dam-break-front-martin-moyce-1952.csv.
#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdlib>

#include "test_helpers.hpp"
#include "valvefsi/fluid/standard_scenes.hpp"

namespace valvefsi::fluid {
namespace {

// Runs the dam break and returns the largest relative front error over the measured
// points that lie inside the tank (Z < 3.8: the front reaches the far wall at Z = 4).
double worst_front_error(double dp, double* lost) {
  auto db = dam_break_2d(dp);
  FluidSolver<2> solver(db.settings, fill_particles(db.scene, db.settings));
  const double a = 1.0, g = 9.81;
  const auto data = testing::read_two_column_csv(VALVEFSI_FLUID_TEST_DATA "/dam-break-front-martin-moyce-1952.csv");
  EXPECT_GE(data.size(), 10u);
  double worst = 0;
  for (const auto& [T, Z] : data) {
    if (Z >= 3.8) break;
    solver.advance_to(T / std::sqrt(2.0 * g / a));
    const double z_sph = testing::fluid_extent(solver, 0) / a;
    const double error = (z_sph - Z) / Z;
    spdlog::info("dam break dp = {} m: T = {:.3f}  Z measured {:.3f}  SPH {:.3f}  ({:+.1f} %)", dp, T, Z, z_sph, 100 * error);
    worst = std::max(worst, std::abs(error));
  }
  *lost = static_cast<double>(solver.lost_count());
  return worst;
}

TEST(DamBreak, CoarseFrontFollowsMartinMoyce) {
  double lost = 0;
  const double worst = worst_front_error(0.04, &lost);
  EXPECT_EQ(lost, 0);
  EXPECT_LT(worst, 0.15);
}

}  // namespace
}  // namespace valvefsi::fluid
