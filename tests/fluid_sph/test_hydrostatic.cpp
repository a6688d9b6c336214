// A still water column (1 m deep in a 1 m wide tank) must hold the hydrostatic pressure
// profile rho g (H - y) without drifting, and the fluid's force on the tank must equal the
// water's weight (action = reaction between fluid and dummy particles).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "valvefsi/fluid/fluid_solver.hpp"
#include "valvefsi/fluid/geometry.hpp"
#include "valvefsi/fluid/probes.hpp"

namespace valvefsi::fluid {
namespace {

struct Column {
  FluidSettings<2> settings;
  SceneGeometry<2> scene;
};

Column water_column(double dp, KernelType kernel) {
  Column c;
  auto& s = c.settings;
  s.particle_spacing = dp;
  s.kernel = kernel;
  s.rest_density = 1000.0;
  s.dynamic_viscosity = 1e-3;
  s.artificial_viscosity = 0.02;  // damps the acoustic start-up transient, as in DualSPHysics' still-water cases
  s.gravity = {0.0, -9.81};
  s.sound_speed = 20.0 * std::sqrt(9.81 * 1.0);
  s.domain_lower = {-0.5, -0.5};
  s.domain_upper = {1.5, 2.0};
  c.scene.walls.push_back(container_box<2>({0.0, 0.0}, {1.0, 1e9}));
  c.scene.fluid.push_back({{0.0, 0.0}, {1.0, 1.0}, {}, {}});
  return c;
}

void check_column(KernelType kernel) {
  const double rho = 1000.0, g = 9.81, H = 1.0, dp = 0.05;
  auto c = water_column(dp, kernel);
  FluidSolver<2> solver(c.settings, fill_particles(c.scene, c.settings));
  const double mass = static_cast<double>(solver.particles().count(Kind::fluid)) * c.settings.particle_mass();

  auto profile_error = [&] {
    double worst = 0;
    for (double y : {0.2, 0.4, 0.6, 0.8}) {
      const double p = pressure_at<2>(solver, {0.5, y});
      worst = std::max(worst, std::abs(p - rho * g * (H - y)) / (rho * g * H));
    }
    return worst;
  };
  // The lattice start settles (particles rearrange) during the first ~2 s; drift is judged after.
  solver.advance_to(2.0);
  const double p_bottom_1 = pressure_at<2>(solver, {0.5, 0.1});
  EXPECT_LT(profile_error(), 0.03);
  solver.request_body_forces();
  solver.advance_to(3.0);
  const double p_bottom_2 = pressure_at<2>(solver, {0.5, 0.1});
  EXPECT_LT(profile_error(), 0.03);
  // No drift between 2 s and 3 s.
  EXPECT_LT(std::abs(p_bottom_2 - p_bottom_1), 0.01 * rho * g * H);
  // Nearly at rest: kinetic energy below 1e-4 of the column's potential energy.
  EXPECT_LT(kinetic_energy<2>(solver), 1e-4 * mass * g * H / 2);
  // The tank carries the water's weight.
  EXPECT_NEAR(solver.body_forces()[0][1], -mass * g, 0.02 * mass * g);
  EXPECT_NEAR(solver.body_forces()[0][0], 0.0, 0.01 * mass * g);
  EXPECT_EQ(solver.lost_count(), 0u);
}

// A density band narrower than the column's own hydrostatic compression (rho g H / c0^2 = 0.25 %
// at the floor) takes out the deepest particles: each is named with where and how.
TEST(Hydrostatic, ParticlesTakenOutForTheirDensityAreNamed) {
  auto c = water_column(0.05, KernelType::cubic_spline);
  c.settings.max_density_deviation = 0.001;
  FluidSolver<2> solver(c.settings, fill_particles(c.scene, c.settings));
  solver.advance_to(0.3);
  const auto& named = solver.named_losses();
  ASSERT_GT(solver.density_out_of_range_count(), 0u);
  EXPECT_EQ(named.size(), std::min(solver.density_out_of_range_count(), FluidSolver<2>::kNamedLosses));
  std::vector<std::uint32_t> ids;
  for (const auto& l : named) {
    EXPECT_GT(std::abs(l.density / 1000.0 - 1.0), 0.001);  // outside the band
    EXPECT_LT(std::abs(l.density / 1000.0 - 1.0), 0.01);
    EXPECT_GT(l.time, 0.0);
    EXPECT_LE(l.time, 0.3 + 1e-12);
    EXPECT_GT(l.step, 0);
    EXPECT_GE(l.position[0], 0.0);                          // in the tank
    EXPECT_LE(l.position[0], 1.0);
    // deep enough for rho g d / c0^2 to leave the band: d > 0.4 m at rest, half that with the
    // lattice start's overshoot (at most twice the static compression)
    EXPECT_LT(l.position[1], 1.0 - 0.5 * 0.001 * c.settings.sound_speed * c.settings.sound_speed / 9.81);
    EXPECT_FALSE(l.near_surface);
    ids.push_back(l.id);
  }
  std::sort(ids.begin(), ids.end());
  EXPECT_EQ(std::adjacent_find(ids.begin(), ids.end()), ids.end());  // each once
}

TEST(Hydrostatic, CubicSplineColumnHoldsProfile) { check_column(KernelType::cubic_spline); }
TEST(Hydrostatic, WendlandColumnHoldsProfile) { check_column(KernelType::wendland_c2); }

}  // namespace
}  // namespace valvefsi::fluid
