// A plate floor that engages once reached (FluidSettings::plate_floor_once_reached): a 2D
// channel closed at its right end, its left end a plate driven at p(t) = A sin(wt) (T = 0.5 s):
// the drive rises from 0 through the floor F = A / 2 at t = T/12, then falls below 0 after T/2.
//  1. Until the drive first reaches F the plate and every particle move bit for bit as without
//     any option (the floor-from-start option instead drives the plate at F from t = 0).
//  2. From then on the plate's drive (prescribed + common level) never falls below F, and the
//     plate stays on the fluid; with the plain never-pull floor of 0 the released column kicks
//     the plate upstream and it coasts away from the blood (the 2D valve's diastole).
//  3. The reached flag survives a checkpoint and a restart file (and is replayed from the drive
//     for restart files written before the flag existed).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "valvefsi/fluid/fluid_solver.hpp"
#include "valvefsi/fluid/geometry.hpp"

namespace valvefsi::fluid {
namespace {

constexpr double dp = 0.02, L = 1.0, H = 0.2, rho = 1000.0, c0 = 20.0, T = 0.5, A = 1256.6, F = 0.5 * A;
const double omega = 2.0 * std::numbers::pi / T;

enum class Drive { plain, never_pull, floor_from_start, floor_once_reached };

FluidSolver<2> channel(Drive drive) {
  FluidSettings<2> s;
  s.particle_spacing = dp;
  s.rest_density = rho;
  s.sound_speed = c0;
  s.dynamic_viscosity = 1e-3;
  s.artificial_viscosity = 0.02;
  s.plates_never_pull = drive != Drive::plain;
  s.plate_pressure_floor = drive == Drive::floor_from_start || drive == Drive::floor_once_reached ? F : 0.0;
  s.plate_floor_once_reached = drive == Drive::floor_once_reached;
  s.domain_lower = {-1.5, -0.2};
  s.domain_upper = {1.5, 0.4};
  SceneGeometry<2> scene;
  scene.walls.push_back(half_space<2>({0.0, 0.0}, {0.0, 1.0}));
  scene.walls.push_back(half_space<2>({0.0, H}, {0.0, -1.0}));
  scene.walls.push_back(solid_box<2>({L, -4 * dp}, {L + 4 * dp, H + 4 * dp}));
  scene.plates.push_back(solid_box<2>({-4 * dp, 0.0}, {0.0, H}));
  scene.fluid.push_back({{0.0, 0.0}, {L, H}, {}, [](const Vec<2>&) { return 0.0; }});
  Particles<2> particles = fill_particles(scene, s);
  std::vector<PressurePlate<2>> plates(1);
  std::size_t count = 0;
  for (std::size_t i = 0; i < particles.size(); ++i) count += particles.body[i] == 1;
  plates[0].normal = {1.0, 0.0};
  plates[0].area = H;
  plates[0].mass = static_cast<double>(count) * s.particle_mass();
  plates[0].pressure = [](double t) { return A * std::sin(omega * t); };
  return FluidSolver<2>(s, std::move(particles), std::move(plates));
}

// Distance from the plate's face to the nearest fluid particle, beyond the dp/2 at rest (m).
double plate_gap(const FluidSolver<2>& solver) {
  double first = 1e300;
  const auto& p = solver.particles();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.kind[i] == Kind::fluid) first = std::min(first, p.position[0][i]);
  return first - solver.plates()[0].displacement - 0.5 * dp;
}

bool same_state(const FluidSolver<2>& a, const FluidSolver<2>& b) {
  if (a.time() != b.time() || a.plates()[0].displacement != b.plates()[0].displacement ||
      a.plates()[0].velocity != b.plates()[0].velocity || a.particles().size() != b.particles().size())
    return false;
  for (int d = 0; d < 2; ++d)
    if (a.particles().position[d] != b.particles().position[d] || a.particles().velocity[d] != b.particles().velocity[d])
      return false;
  return a.particles().density_excess == b.particles().density_excess;
}

TEST(PlateFloorOnceReached, IdenticalToNoOptionUntilReachedThenNeverBelowTheFloor) {
  FluidSolver<2> once = channel(Drive::floor_once_reached);
  FluidSolver<2> plain = channel(Drive::plain);
  FluidSolver<2> from_start = channel(Drive::floor_from_start);
  EXPECT_FALSE(once.plate_floor_reached());
  EXPECT_EQ(once.plate_pressure_level(), 0.0);
  EXPECT_EQ(from_start.plate_pressure_level(), F);  // the old option drives at F from t = 0

  // 1. Lockstep until the drive reaches F (at t = T/12 = 0.0417 s): bit for bit.
  long identical_steps = 0;
  while (!once.plate_floor_reached()) {
    ASSERT_TRUE(same_state(once, plain)) << "differs from the run without the option at t = " << once.time();
    ASSERT_LT(once.time(), T / 4) << "the floor was never reached";
    once.step();
    plain.step();
    ++identical_steps;
  }
  const double reached_at = once.time();
  EXPECT_GE(A * std::sin(omega * reached_at), F);
  EXPECT_LT(reached_at - once.time_step(), T / 12) << "reached one step late";
  EXPECT_GE(reached_at, T / 12);
  // The step that reached it had level 0 and so the same drive: still identical.
  EXPECT_TRUE(same_state(once, plain));
  from_start.advance_to(reached_at);
  EXPECT_NE(from_start.plates()[0].displacement, once.plates()[0].displacement);

  // 2. From then on, to 2T: the drive never below F. From T on the drive is F (at 5T/12 the
  // sine fell below it): the column rings about the compression F L / (rho0 c0^2) against the
  // closed end, and the fluid presses on the plate with F on average.
  struct Motion {
    double lowest_drive = 1e300, largest_gap = 0.0, lowest = 1e300, highest = -1e300, displacement_sum = 0.0, time_sum = 0.0;
  };
  auto follow = [](FluidSolver<2>& solver) {
    Motion m;
    while (solver.time() < 2 * T) {
      solver.step();
      const auto& plate = solver.plates()[0];
      m.lowest_drive = std::min(m.lowest_drive, plate.pressure(solver.time()) + solver.plate_pressure_level());
      m.largest_gap = std::max(m.largest_gap, plate_gap(solver));
      if (solver.time() < T) continue;
      m.lowest = std::min(m.lowest, plate.displacement);
      m.highest = std::max(m.highest, plate.displacement);
      m.displacement_sum += plate.displacement * solver.time_step();
      m.time_sum += solver.time_step();
    }
    return m;
  };
  const Motion floored = follow(once);
  FluidSolver<2> never_pull = channel(Drive::never_pull);
  const Motion floor0 = follow(never_pull);
  const double compression = F * L / (rho * c0 * c0);
  for (const auto* m : {&floored, &floor0})
    std::printf("%s: lowest drive %.1f Pa, largest gap %.3g dp; over T..2T plate between %.2f and %.2f mm, mean %.2f mm "
                "(quasi-static compression under the floor %.2f mm)\n",
                m == &floored ? "floor once reached" : "never pull, floor 0", m->lowest_drive, m->largest_gap / dp,
                1e3 * m->lowest, 1e3 * m->highest, 1e3 * m->displacement_sum / m->time_sum, 1e3 * compression);
  std::printf("floor once reached: %ld identical steps to t = %.5f s (T/12 = %.5f s); lost %zu; plate at 2T %.2f mm, %.3f m/s "
              "(floor 0: %.2f mm, %.3f m/s)\n",
              identical_steps, reached_at, T / 12, once.lost_count(), 1e3 * once.plates()[0].displacement, once.plates()[0].velocity,
              1e3 * never_pull.plates()[0].displacement, never_pull.plates()[0].velocity);
  EXPECT_GE(floored.lowest_drive, F * (1 - 1e-12));
  EXPECT_LT(floored.largest_gap, 0.1 * dp);
  EXPECT_EQ(once.lost_count(), 0u);
  EXPECT_NEAR(floored.displacement_sum / floored.time_sum, compression, compression);
  EXPECT_GT(floored.lowest, -3 * compression);
  // Without the floor the released column kicks the plate upstream and nothing brings it back.
  EXPECT_LT(never_pull.plates()[0].displacement, -10 * compression);
  EXPECT_LT(never_pull.plates()[0].velocity, 0.0);
}

TEST(PlateFloorOnceReached, TheFlagSurvivesCheckpointsAndRestartFiles) {
  FluidSolver<2> run = channel(Drive::floor_once_reached);
  run.advance_to(0.02);
  run.save_checkpoint();
  run.advance_to(0.6 * T);  // reached, and the drive below the floor: the level acts
  ASSERT_TRUE(run.plate_floor_reached());
  ASSERT_GT(run.plate_pressure_level(), 0.0);
  const auto state = run.restart_state();
  ASSERT_TRUE(state.has_value());

  FluidSolver<2> resumed = channel(Drive::floor_once_reached);
  resumed.load_restart_state(*state);
  EXPECT_TRUE(resumed.plate_floor_reached());
  // A file written before the flag existed: the flag is replayed from the drive.
  std::vector<NamedArray> old_file;
  for (const auto& a : *state)
    if (a.name != "plate_floor_reached") old_file.push_back(a);
  ASSERT_EQ(old_file.size() + 1, state->size());
  FluidSolver<2> resumed_old = channel(Drive::floor_once_reached);
  resumed_old.load_restart_state(old_file);
  EXPECT_TRUE(resumed_old.plate_floor_reached());

  run.advance_to(0.7 * T);
  resumed.advance_to(0.7 * T);
  resumed_old.advance_to(0.7 * T);
  EXPECT_TRUE(same_state(run, resumed));
  EXPECT_TRUE(same_state(run, resumed_old));

  // A checkpoint taken before the floor was reached brings the flag back with the state.
  FluidSolver<2> early = channel(Drive::floor_once_reached);
  early.advance_to(0.02);
  early.save_checkpoint();
  early.advance_to(0.1);
  ASSERT_TRUE(early.plate_floor_reached());
  early.restore_checkpoint();
  EXPECT_FALSE(early.plate_floor_reached());
  EXPECT_NEAR(early.plate_pressure_level(0.6 * T), -A * std::sin(omega * 0.6 * T), 1e-9);  // floor 0: only kept from pulling ...
  early.advance_to(0.1);
  EXPECT_TRUE(early.plate_floor_reached());
  EXPECT_NEAR(early.plate_pressure_level(0.6 * T), F - A * std::sin(omega * 0.6 * T), 1e-9);  // ... until reached
}

// The plates' forces are booked per row of cells and summed in row order, so a run on two threads
// is the run on one, bit for bit, step by step (per-thread sums made them differ in the last bit,
// and two runs on two threads could differ under load).
TEST(PlateForces, OneAndTwoThreadsGiveTheSameRunBitForBit) {
  FluidSolver<2> one = channel(Drive::plain);
  FluidSolver<2> two = channel(Drive::plain);
  for (int step = 0; step < 400; ++step) {
    omp_set_num_threads(1);
    one.step();
    omp_set_num_threads(2);
    two.step();
    ASSERT_EQ(one.plates()[0].fluid_force[0], two.plates()[0].fluid_force[0]) << "step " << step;
    ASSERT_TRUE(same_state(one, two)) << "step " << step << ", t = " << one.time();
  }
  EXPECT_GT(std::abs(one.plates()[0].fluid_force[0]), 0.0);  // the plate pushed on the fluid
}

}  // namespace
}  // namespace valvefsi::fluid
