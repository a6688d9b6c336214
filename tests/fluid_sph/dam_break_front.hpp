#pragma once
// The dam-break comparison shared by the CI (coarse) and validation (fine) tests.
#include <spdlog/spdlog.h>

#include <cmath>

#include "test_helpers.hpp"
#include "valvefsi/fluid/standard_scenes.hpp"

namespace valvefsi::fluid::testing {

// Runs the dam break and returns the largest relative front error over the measured
// points that lie inside the tank (Z < 3.8: the front reaches the far wall at Z = 4).
inline double worst_front_error(double dp, double* lost) {
  auto db = dam_break_2d(dp);
  FluidSolver<2> solver(db.settings, fill_particles(db.scene, db.settings));
  const double a = 1.0, g = 9.81;
  const auto data = read_two_column_csv(VALVEFSI_FLUID_TEST_DATA "/dam-break-front-martin-moyce-1952.csv");
  EXPECT_GE(data.size(), 10u);
  double worst = 0;
  for (const auto& [T, Z] : data) {
    if (Z >= 3.8) break;
    solver.advance_to(T / std::sqrt(2.0 * g / a));
    const double z_sph = fluid_extent(solver, 0) / a;
    const double error = (z_sph - Z) / Z;
    spdlog::info("dam break dp = {} m: T = {:.3f}  Z measured {:.3f}  SPH {:.3f}  ({:+.1f} %)", dp, T, Z, z_sph, 100 * error);
    worst = std::max(worst, std::abs(error));
  }
  *lost = static_cast<double>(solver.lost_count());
  return worst;
}

}  // namespace valvefsi::fluid::testing
