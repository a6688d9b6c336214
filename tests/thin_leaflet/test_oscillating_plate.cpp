// 2D proof (c): a thin plate (width b) oscillating normal to itself in a closed box of water,
// X = -A cos(wt). Potential flow gives the in-phase force m w^2 X with the added mass
// m = rho pi (b/2)^2 times 1.028 for this box (L = H = 4b; fluid_sph/thin_wall/scripts/
// plate_added_mass.py, extrapolated finite volumes). KC = 2 pi A / b = 0.31, Stokes layer
// sqrt(2 nu / w) = 0.004 b. The force is fitted to alpha w^2 X + beta w V + c over the
// periods after the first.
// Verification (b/10): stable, no leak, the fit explains the signal, the in-phase part has
// the right sign and is no smaller than potential flow. Validation (b/20): the issue's
// target, within 10 % of potential flow -- NOT met yet (the free edge acts wider than it is,
// docs/thin-leaflet.md records the measurements).
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "valvefsi/fluid/thin_wall/scenes_2d.hpp"
#include "valvefsi/fluid/thin_wall/solver_run_2d.hpp"

namespace valvefsi::fluid::thin_wall {
namespace {

struct PlateFit {
  double in_phase = 0, velocity_phase = 0, residual = 0;  // over m (A w^2 for the residual)
  std::size_t leaks = 0, corrections = 0;
  double max_speed = 0;
};

PlateFit run_plate(double dp, double end_time) {
  OscillatingPlate plate;
  plate.amplitude = 0.005;
  plate.period = 0.5;
  auto scene = oscillating_plate_box(dp, plate);
  scene.fluid.shifting = 1.0;  // without it the flow round the edges blows up within ~1 s
  ThinWallSolverRun2D flow(std::move(scene));
  const double w = 2 * std::numbers::pi / plate.period;
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  std::vector<std::array<double, 4>> samples;
  PlateFit fit;
  while (flow.time() < end_time - 1e-9) {
    flow.step();
    const auto& p = flow.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.kind[i] == Kind::fluid) fit.max_speed = std::max(fit.max_speed, std::hypot(double(p.velocity[0][i]), double(p.velocity[1][i])));
    if (flow.time() < plate.period) continue;
    const auto& wall = flow.wall_model().wall();
    const Eigen::Vector3d row(w * w * wall.position[0][0], w * wall.velocity[0][0], 1.0);
    const double f = flow.wall_force()[0];
    normal += row * row.transpose();
    rhs += row * f;
    samples.push_back({row[0], row[1], row[2], f});
  }
  const Eigen::Vector3d c = normal.ldlt().solve(rhs);
  const double m = 1000.0 * std::numbers::pi * std::pow(plate.plate_width / 2, 2) * 1.028;
  double r2 = 0;
  for (const auto& s : samples) r2 += std::pow(s[3] - (c[0] * s[0] + c[1] * s[1] + c[2] * s[2]), 2);
  fit.in_phase = c[0] / m;
  fit.velocity_phase = c[1] / m;
  fit.residual = std::sqrt(r2 / static_cast<double>(samples.size())) / (m * plate.amplitude * w * w);
  fit.leaks = flow.wall_model().counters().leaks;
  fit.corrections = flow.wall_model().counters().corrections;
  std::printf("plate dp = b/%.0f: in-phase %.3f, velocity-phase %.3f, residual %.3f (of m A w^2), max speed %.3f m/s "
              "(plate %.3f), corrections %zu, leaks %zu\n",
              plate.plate_width / dp, fit.in_phase, fit.velocity_phase, fit.residual, fit.max_speed, plate.amplitude * w,
              fit.corrections, fit.leaks);
  return fit;
}

// One source, two executables: THIN_WALL_PLATE_VALIDATION selects the long fine run.
#if !THIN_WALL_PLATE_VALIDATION
TEST(ThinWallOscillatingPlate, StableLeakFreeAndInertialAtTenParticlesAcross) {
  omp_set_num_threads(1);  // ~1600 particles: threading overhead exceeds the work
  const PlateFit fit = run_plate(0.01, 1.5);
  EXPECT_EQ(fit.leaks, 0u);
  EXPECT_LT(fit.max_speed, 10 * 0.005 * 4 * std::numbers::pi);  // edge flow stays bounded
  EXPECT_LT(fit.residual, 1.0);                                 // the harmonic fit carries the signal
  EXPECT_GT(fit.in_phase, 1.0);   // measured 1.55: the edge acts wider, never narrower
  EXPECT_LT(fit.in_phase, 2.0);
  EXPECT_LT(fit.velocity_phase, 0.0);  // dissipative
}

#else
TEST(ThinWallOscillatingPlate, AddedMassWithinTenPercentAtTwentyParticlesAcross) {
  const PlateFit fit = run_plate(0.005, 2.5);
  EXPECT_EQ(fit.leaks, 0u);
  EXPECT_NEAR(fit.in_phase, 1.0, 0.10);  // the target; open (docs/thin-leaflet.md)
}
#endif

}  // namespace
}  // namespace valvefsi::fluid::thin_wall
