// Plates that never pull (FluidSettings::plates_never_pull): a 2D channel between two plates
// whose prescribed pressures are p_left = P sin(wt) and p_right = -P sin(wt), so the
// difference reverses sign at T/2, without background pressure.
//  1. The common level at chosen times is max(0, floor - background - min_k p_k(t)).
//  2. With the level both plates stay on the fluid (no gap opens between a plate's face and the
//     fluid beyond the dp/2 at rest, no particle is lost) and the column moves as the rigid body of mass M under
//     2 P A sin(wt): x(t) = 2 P A / (M w) (t - sin(wt) / w). With the old drive the left plate,
//     driven below zero in the second half period, leaves the blood (which cannot pull it).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "valvefsi/fluid/fluid_solver.hpp"
#include "valvefsi/fluid/geometry.hpp"

namespace valvefsi::fluid {
namespace {

constexpr double dp = 0.02, L = 1.0, H = 0.2, rho = 1000.0, c0 = 20.0, T = 0.5, P = 1256.6;
const double omega = 2.0 * std::numbers::pi / T;

FluidSolver<2> channel(bool never_pull, double floor = 0.0, double background = 0.0) {
  FluidSettings<2> s;
  s.particle_spacing = dp;
  s.rest_density = rho;
  s.sound_speed = c0;
  s.dynamic_viscosity = 1e-3;
  s.artificial_viscosity = 0.02;
  s.background_pressure = background;
  s.plates_never_pull = never_pull;
  s.plate_pressure_floor = floor;
  s.domain_lower = {-1.5, -0.2};
  s.domain_upper = {2.5, 0.4};
  SceneGeometry<2> scene;
  scene.walls.push_back(half_space<2>({0.0, 0.0}, {0.0, 1.0}));
  scene.walls.push_back(half_space<2>({0.0, H}, {0.0, -1.0}));
  scene.plates.push_back(solid_box<2>({-4 * dp, 0.0}, {0.0, H}));
  scene.plates.push_back(solid_box<2>({L, 0.0}, {L + 4 * dp, H}));
  scene.fluid.push_back({{0.0, 0.0}, {L, H}, {}, [](const Vec<2>&) { return 0.0; }});
  Particles<2> particles = fill_particles(scene, s);
  std::vector<PressurePlate<2>> plates(2);
  for (int k = 0; k < 2; ++k) {
    std::size_t count = 0;
    for (std::size_t i = 0; i < particles.size(); ++i) count += particles.body[i] == k + 1;
    plates[k].normal = {k == 0 ? 1.0 : -1.0, 0.0};
    plates[k].area = H;
    plates[k].mass = static_cast<double>(count) * s.particle_mass();
    const double sign = k == 0 ? 1.0 : -1.0;
    plates[k].pressure = [sign](double t) { return sign * P * std::sin(omega * t); };
  }
  return FluidSolver<2>(s, std::move(particles), std::move(plates));
}

TEST(PlatesNeverPull, CommonLevelAtChosenTimes) {
  const FluidSolver<2> off = channel(false);
  EXPECT_EQ(off.plate_pressure_level(0.3 * T), 0.0);
  const FluidSolver<2> on = channel(true);
  EXPECT_NEAR(on.plate_pressure_level(0.0), 0.0, 1e-9);
  EXPECT_NEAR(on.plate_pressure_level(T / 8), P * std::sin(std::numbers::pi / 4), 1e-9);  // right plate lowest
  EXPECT_NEAR(on.plate_pressure_level(T / 4), P, 1e-9);
  EXPECT_NEAR(on.plate_pressure_level(3 * T / 4), P, 1e-9);                             // left plate lowest
  EXPECT_NEAR(on.plate_pressure_level(T / 2), 0.0, 1e-6);
  const FluidSolver<2> floored = channel(true, 100.0);
  EXPECT_NEAR(floored.plate_pressure_level(0.0), 100.0, 1e-9);
  EXPECT_NEAR(floored.plate_pressure_level(T / 4), P + 100.0, 1e-9);
  // A background pressure counts towards the floor: only what is missing is added.
  const FluidSolver<2> background = channel(true, 0.0, 500.0);
  EXPECT_NEAR(background.plate_pressure_level(T / 4), P - 500.0, 1e-9);
  EXPECT_NEAR(background.plate_pressure_level(T / 8), P * std::sin(std::numbers::pi / 4) - 500.0, 1e-9);
  EXPECT_EQ(background.plate_pressure_level(0.0), 0.0);
}

struct ChannelRun {
  double largest_gap;          // largest distance between a plate's face and the fluid, beyond the dp/2 at rest (m)
  double largest_compression;  // largest shortening of the column between the plates (m)
  double left_displacement;
  std::size_t lost;
};

ChannelRun run(bool never_pull, double floor = 0.0) {
  FluidSolver<2> solver = channel(never_pull, floor);
  ChannelRun r{};
  while (solver.time() < T * (1 - 1e-12)) {
    solver.advance_to(std::min(T, solver.time() + 0.01));
    const auto& plates = solver.plates();
    // The left plate moves along +x, the right one along -x: their sum is the stretch.
    r.largest_compression = std::max(r.largest_compression, plates[0].displacement + plates[1].displacement);
    // The left face is at x = displacement_0, the right one at L - displacement_1.
    double first = 1e300, last = -1e300;
    const auto& p = solver.particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.kind[i] != Kind::fluid) continue;
      first = std::min(first, p.position[0][i]);
      last = std::max(last, p.position[0][i]);
    }
    const double gap = std::max(first - plates[0].displacement, (L - plates[1].displacement) - last) - 0.5 * dp;
    r.largest_gap = std::max(r.largest_gap, gap);
  }
  r.left_displacement = solver.plates()[0].displacement;
  r.lost = solver.lost_count();
  return r;
}

TEST(PlatesNeverPull, BothPlatesStayOnTheFluidWhenTheDifferenceReverses) {
  FluidSolver<2> probe = channel(true);
  double mass = L * H * rho;
  for (const auto& plate : probe.plates()) mass += plate.mass;
  const double rigid = 2 * P * H / (mass * omega) * (T - std::sin(omega * T) / omega);
  const ChannelRun level = run(true);
  const ChannelRun old = run(false);
  // The level (up to P) and the drive (2P at one plate, 0 at the other) compress the column by
  // about L P / (rho0 c0^2) on average, plus the acoustic start-up.
  const double quasi_static = L * P / (rho * c0 * c0);
  std::printf("plates never pull: largest gap %.3g dp, largest compression %.3g dp (quasi-static %.3g dp), left plate at T "
              "%.4f m (rigid column %.4f m, %+.2f %%), lost %zu\n",
              level.largest_gap / dp, level.largest_compression / dp, quasi_static / dp, level.left_displacement, rigid,
              100 * (level.left_displacement / rigid - 1), level.lost);
  std::printf("old drive: largest gap %.3g dp, largest compression %.3g dp, left plate at T %.4f m, lost %zu\n", old.largest_gap / dp,
              old.largest_compression / dp, old.left_displacement, old.lost);
  EXPECT_LT(level.largest_gap, 0.1 * dp);
  EXPECT_LT(level.largest_compression, 3 * quasi_static);
  // Wall friction and the plate rims (docs: a plate sustains a few % more than prescribed) slow it.
  EXPECT_NEAR(level.left_displacement, rigid, 0.1 * rigid);
  EXPECT_EQ(level.lost, 0u);
  EXPECT_GT(old.largest_gap, 10 * dp);  // the left plate flew off
}

}  // namespace
}  // namespace valvefsi::fluid
