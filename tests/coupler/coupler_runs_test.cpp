// The real coupler with real stand-in processes: each scheme reproduces the exact solution of
// its discrete problem, the interface conserves force and power, and a fluid can be swapped
// for another without touching the coupler or the solid.
//
// The solid stand-in is a rigid plate (area A = 2e-4 m^2, mass m, spring k) moving along z; its
// window update is exact for a constant load, so every expected value below is the closed-form
// or the few-line recurrence of the scheme, not a stored number.

#include <gtest/gtest.h>

#include <cmath>

#include "coupled_run.hpp"

namespace valvefsi::testing {
namespace {

constexpr double kArea = 0.02 * 0.01;  // standin_solid_plate's default plate
constexpr double kMass = 1e-3, kStiffness = 10.0, kPressure = 100.0;
const double kOmega = std::sqrt(kStiffness / kMass);
const std::vector<std::string> kPlateArgs = {"--mass", "1e-3", "--stiffness", "10"};

struct Plate {
  double z = 0.0, v = 0.0;
};

Plate advance(Plate s, double force, double dt) {
  const double z_eq = force / kStiffness, c = std::cos(kOmega * dt), sn = std::sin(kOmega * dt);
  return {z_eq + (s.z - z_eq) * c + s.v / kOmega * sn, -(s.z - z_eq) * kOmega * sn + s.v * c};
}

RunSpec plate_run(const std::string& name, double end_time, const std::string& coupling, const std::string& fluid,
                  std::vector<std::string> fluid_args) {
  RunSpec spec;
  spec.name = name;
  spec.end_time = end_time;
  spec.coupling = coupling;
  spec.fluid = fluid;
  spec.fluid_args = std::move(fluid_args);
  spec.solid_args = kPlateArgs;
  return spec;
}

void expect_all_ended_ok(CoupledRun& run) {
  const auto codes = run.wait_all(std::chrono::seconds(60));
  for (const char* role : {"coupler", "solid", "fluid"}) {
    ASSERT_EQ(codes.count(role), 1u) << role << " did not end";
    EXPECT_EQ(codes.at(role), 0) << role << " log:\n" << (role == std::string("coupler") ? run.coupler->log_text()
                                                         : role == std::string("solid") ? run.solid->log_text()
                                                                                          : run.fluid->log_text());
  }
}

TEST(CoupledRun, SerialExplicitPlateUnderPressureMatchesExactSolutionAndConservesForceAndPower) {
  CoupledRun run(plate_run("serial", 0.05, "window_size: 1e-3", "standin_fluid_pressure", {"--pressure", "100"}));
  expect_all_ended_ok(run);
  const double force = kPressure * kArea;
  const double exact = force / kStiffness * (1.0 - std::cos(kOmega * 0.05));
  EXPECT_NEAR(final_plate_z(run.solid->log_text()), exact, 1e-9 * exact);

  const auto series = run.dir / "coupling_series.h5";
  const auto time = read_series(series, "time");
  ASSERT_EQ(time.size(), 50u);
  EXPECT_NEAR(time.back(), 0.05, 1e-15);
  const auto fluid_force = read_series(series, "force_fluid");
  const auto solid_force = read_series(series, "force_solid");
  const auto fluid_power = read_series(series, "power_fluid");
  const auto solid_power = read_series(series, "power_solid");
  for (std::size_t row = 0; row < time.size(); ++row) {
    EXPECT_NEAR(fluid_force[3 * row + 2], force, 1e-12 * force);                     // p A, by the fluid
    EXPECT_NEAR(solid_force[3 * row + 2], fluid_force[3 * row + 2], 1e-12 * force);  // conservative mapping
    EXPECT_NEAR(solid_power[row], fluid_power[row], 1e-12 * force * 1.0);            // power preserved
  }
  EXPECT_GT(std::abs(fluid_power[10]), 1e-5);  // the plate moves: the power check is not 0 = 0
}

TEST(CoupledRun, TcpEndpointGivesTheSameAnswer) {
  RunSpec spec = plate_run("tcp", 0.05, "window_size: 1e-3", "standin_fluid_pressure", {"--pressure", "100"});
  spec.endpoint = "tcp://127.0.0.1:47391";
  CoupledRun run(spec);
  expect_all_ended_ok(run);
  const double exact = kPressure * kArea / kStiffness * (1.0 - std::cos(kOmega * 0.05));
  EXPECT_NEAR(final_plate_z(run.solid->log_text()), exact, 1e-9 * exact);
}

TEST(CoupledRun, ParallelExplicitLagsTheLoadsByOneWindow) {
  CoupledRun run(plate_run("parallel", 0.05, "scheme: PARALLEL_EXPLICIT window_size: 1e-3", "standin_fluid_pressure",
                           {"--pressure", "100"}));
  expect_all_ended_ok(run);
  // The solid sees no load in the first window, then p A: z(T) = pA/k (1 - cos w (T - dt)).
  const double exact = kPressure * kArea / kStiffness * (1.0 - std::cos(kOmega * (0.05 - 1e-3)));
  EXPECT_NEAR(final_plate_z(run.solid->log_text()), exact, 1e-9 * exact);
}

TEST(CoupledRun, SwappedFluidDamperReproducesItsExplicitRecurrence) {
  // Same coupler, same solid, another fluid program: f = (p - c v_z) per unit area, with the
  // window-start velocity in the serial explicit scheme.
  const double c = 2000.0, dt = 1e-3;
  CoupledRun run(plate_run("swap", 0.05, "window_size: 1e-3", "standin_fluid_damper",
                           {"--pressure", "100", "--damping", "2000"}));
  expect_all_ended_ok(run);
  Plate plate;
  for (int n = 0; n < 50; ++n) plate = advance(plate, (kPressure - c * plate.v) * kArea, dt);
  EXPECT_NEAR(final_plate_z(run.solid->log_text()), plate.z, 1e-9 * std::abs(plate.z));
  EXPECT_NE(run.fluid->log_text().find("coupled with standin_solid_plate"), std::string::npos);
}

// Serial implicit on the damper: per window the fixed point z1 = S(F(z1)) with
// F = (p - c (z1 - z0)/dt) A is linear, so the converged answer is known in closed form.
void implicit_damper_converges(const std::string& acceleration, int max_mean_iterations_x10) {
  const double c = 5000.0, dt = 1e-3;
  CoupledRun run(plate_run("implicit-" + acceleration, 0.02,
                           "scheme: SERIAL_IMPLICIT acceleration: " + acceleration +
                               " relative_tolerance: 1e-10 absolute_tolerance: 0 max_iterations: 60 relaxation_factor: 0.5 window_size: 1e-3",
                           "standin_fluid_damper", {"--pressure", "100", "--damping", "5000"}));
  expect_all_ended_ok(run);
  Plate plate;
  const double cosine = std::cos(kOmega * dt), sine = std::sin(kOmega * dt), b = (1.0 - cosine) / kStiffness;
  for (int n = 0; n < 20; ++n) {
    const double a = plate.z * cosine + plate.v / kOmega * sine;
    const double z1 = (a + b * kPressure * kArea + b * c * kArea * plate.z / dt) / (1.0 + b * c * kArea / dt);
    plate = advance(plate, (kPressure - c * (z1 - plate.z) / dt) * kArea, dt);
  }
  EXPECT_NEAR(final_plate_z(run.solid->log_text()), plate.z, 1e-7 * std::abs(plate.z));
  const auto iterations = read_series(run.dir / "coupling_series.h5", "iterations");
  const auto residual = read_series(run.dir / "coupling_series.h5", "relative_residual");
  ASSERT_EQ(iterations.size(), 20u);
  double total = 0.0;
  for (std::size_t i = 0; i < iterations.size(); ++i) {
    total += iterations[i];
    EXPECT_LT(residual[i], 1e-10) << "window " << i;
    EXPECT_GE(iterations[i], 2.0);  // the extrapolated first guess is never the fixed point here
  }
  EXPECT_LE(10.0 * total / 20.0, max_mean_iterations_x10) << acceleration;
}

// The fixed-point map's slope is J = -b c A / dt = -0.50, so constant relaxation with w = 0.5
// contracts by |1 - w (1 - J)| = 0.25 per iteration: <= 17 iterations to 1e-10 from an O(1)
// relative error. Aitken and IQN-ILS solve a linear map in a secant step: about 3 iterations.
TEST(CoupledRun, SerialImplicitConstantRelaxationConvergesToTheFixedPoint) { implicit_damper_converges("CONSTANT_RELAXATION", 170); }
TEST(CoupledRun, SerialImplicitAitkenConvergesToTheFixedPoint) { implicit_damper_converges("AITKEN", 35); }
TEST(CoupledRun, SerialImplicitIqnIlsConvergesToTheFixedPoint) { implicit_damper_converges("IQN_ILS", 35); }

// The absolute criterion ends a window whose solid motion changes by less than
// absolute_tolerance (RMS per node), whatever the relative change: a solid at rest amid fluid
// noise would otherwise never converge. Here the plate moves ~1e-3 m per window, so a 1 m
// tolerance accepts the first pass of every window and 0 never does.
TEST(CoupledRun, SerialImplicitAbsoluteToleranceEndsTheWindow) {
  for (const double tolerance : {0.0, 1.0}) {
    CoupledRun run(plate_run("implicit-absolute-" + std::to_string(static_cast<int>(tolerance)), 0.01,
                             "scheme: SERIAL_IMPLICIT acceleration: IQN_ILS relative_tolerance: 1e-10 "
                             "max_iterations: 60 window_size: 1e-3 absolute_tolerance: " + std::to_string(tolerance),
                             "standin_fluid_damper", {"--pressure", "100", "--damping", "5000"}));
    expect_all_ended_ok(run);
    const auto iterations = read_series(run.dir / "coupling_series.h5", "iterations");
    ASSERT_EQ(iterations.size(), 10u);
    for (std::size_t i = 0; i < iterations.size(); ++i) {
      if (tolerance > 0.0) {
        EXPECT_EQ(iterations[i], 1.0) << "window " << i;
      } else {
        EXPECT_GE(iterations[i], 2.0) << "window " << i;
      }
    }
  }
}

TEST(CoupledRun, WindowIsTheSmallestOfCaseAndProposalsAndLandsOnTheEndTime) {
  RunSpec spec = plate_run("window", 0.0101, "window_size: 1e-3", "standin_fluid_pressure", {"--propose-window", "4e-4"});
  spec.solid_args = {"--propose-window", "6e-4"};
  CoupledRun run(spec);
  expect_all_ended_ok(run);
  const auto size = read_series(run.dir / "coupling_series.h5", "window_size");
  const auto time = read_series(run.dir / "coupling_series.h5", "time");
  ASSERT_EQ(size.size(), 24u);  // 1e-3 first (no proposal yet), then 4e-4 x 22, then the 3e-4 left
  EXPECT_DOUBLE_EQ(size[0], 1e-3);
  for (std::size_t i = 1; i + 1 < size.size(); ++i) EXPECT_DOUBLE_EQ(size[i], 4e-4) << i;
  EXPECT_NEAR(time.back(), 0.0101, 1e-15);
  EXPECT_NEAR(size.back(), 0.0101 - 1e-3 - 22 * 4e-4, 1e-15);
}

}  // namespace
}  // namespace valvefsi::testing
