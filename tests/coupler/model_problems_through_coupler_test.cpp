// The numerics' model problems (coupler/model_problems, theory in docs/coupling-numerics.md)
// run through the REAL coupler as separate processes (stand-ins standin_model_solid/fluid),
// reproducing the analytic limits:
//   incompressible piston: constant relaxation converges only below w = 2 / (1 + m_a/m_s);
//   acoustic piston: serial explicit stable below mu = 2, diverging above; parallel explicit
//   failing earlier, at mu = 2 (sqrt 2 - 1); IQN-ILS converging beyond both;
//   nonlinear fixed point: IQN-ILS finds the known root where plain iteration diverges.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <regex>

#include "coupled_run.hpp"

namespace valvefsi::testing {
namespace {

using namespace std::chrono_literals;

double value_after(const std::string& log, const std::string& label) {
  const std::regex pattern(label + R"( = ([-+0-9.eE]+))");
  std::smatch match;
  if (!std::regex_search(log, match, pattern)) throw std::runtime_error("no '" + label + "' in:\n" + log);
  return std::stod(match[1].str());
}

std::string format(double x) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}

struct Outcome {
  std::map<std::string, int> codes;
  std::string solid_log, coupler_log;
  std::filesystem::path dir;
};

Outcome run(const std::string& name, double end_time, const std::string& coupling, std::vector<std::string> fluid_args,
            std::vector<std::string> solid_args) {
  RunSpec spec;
  spec.name = name;
  spec.end_time = end_time;
  spec.coupling = coupling;
  spec.fluid = "standin_model_fluid";
  spec.fluid_args = std::move(fluid_args);
  spec.solid = "standin_model_solid";
  spec.solid_args = std::move(solid_args);
  CoupledRun run(spec);
  Outcome outcome;
  outcome.codes = run.wait_all(120s);
  outcome.solid_log = run.solid->log_text();
  outcome.coupler_log = run.coupler->log_text();
  outcome.dir = run.dir;
  return outcome;
}

bool all_ok(const Outcome& o) {
  return o.codes.size() == 3 && o.codes.at("coupler") == 0 && o.codes.at("solid") == 0 && o.codes.at("fluid") == 0;
}

// The coupler's own runaway check (coupling.max_interface_speed, 20 m/s against the piston's
// terminal 0.01 m/s) stopped the run with exit code 6, before the stand-in's divergence bound.
bool stopped_as_runaway(const Outcome& o) {
  return o.codes.count("coupler") == 1 && o.codes.at("coupler") == 6 &&
         o.coupler_log.find("the interface is running away") != std::string::npos;
}

// The stop's diagnosis measured the piston's mode at the window's scale (a period of 2-4
// windows) and named the added-mass instability and its remedies (runaway_diagnosis.hpp).
bool named_added_mass(const Outcome& o) {
  std::smatch period;
  return o.coupler_log.find("It grows at the window's scale") != std::string::npos &&
         o.coupler_log.find("added-mass instability") != std::string::npos &&
         o.coupler_log.find("SERIAL_IMPLICIT") != std::string::npos &&
         std::regex_search(o.coupler_log, period, std::regex(R"(equivalent period of ([0-9.]+) windows)")) &&
         std::stod(period[1].str()) >= 2.0 && std::stod(period[1].str()) <= 4.1;
}

// ---------------------------------------------------------------- incompressible piston
// m_s = 4 g, m_a = rho L A = 10 g: limit 2 / 3.5. F_ext = 0.1 N, dt = 1 ms.
constexpr double kStructureMass = 0.004, kAddedMass = 0.01, kExternalForce = 0.1;
const double kPistonLimit = 2.0 / (1.0 + kAddedMass / kStructureMass);
const double kMonolithicAcceleration = kExternalForce / (kStructureMass + kAddedMass);

Outcome incompressible(const std::string& name, double omega, double end_time, int max_iterations) {
  const std::string a0 = format(kMonolithicAcceleration);
  return run(name, end_time,
             "scheme: SERIAL_IMPLICIT acceleration: CONSTANT_RELAXATION window_size: 1e-3 relative_tolerance: 1e-10 absolute_tolerance: 0"
             " max_iterations: " + std::to_string(max_iterations) + " relaxation_factor: " + format(omega),
             {"--model", "incompressible", "--density", "1000", "--column-length", "0.1", "--area", "1e-4",
              "--initial-acceleration", a0},
             {"--model", "piston", "--mass", "0.004", "--external-force", "0.1", "--initial-acceleration", a0,
              "--area", "1e-4", "--divergence-bound", "1e30"});
}

TEST(ModelProblemsThroughCoupler, IncompressiblePistonRelaxationConvergesJustBelowTheAddedMassLimit) {
  const auto below = incompressible("mp-incompressible-below", 0.97 * kPistonLimit, 5e-3, 1000);
  ASSERT_TRUE(all_ok(below)) << below.coupler_log;
  // Converged, the pair is the monolithic piston of mass m_s + m_a: u = a t^2 / 2 exactly (trapezoidal rule).
  const double t = 5e-3, u = 0.5 * kMonolithicAcceleration * t * t;
  EXPECT_NEAR(value_after(below.solid_log, "final u"), u, 1e-7 * u);
  for (double r : read_series(below.dir / "coupling_series.h5", "relative_residual")) EXPECT_LT(r, 1e-10);
}

TEST(ModelProblemsThroughCoupler, IncompressiblePistonRelaxationDivergesJustAboveTheLimit) {
  const auto above = incompressible("mp-incompressible-above", 1.03 * kPistonLimit, 1e-3, 300);
  EXPECT_NE(above.coupler_log.find("not converged after 300 iterations"), std::string::npos) << above.coupler_log;
  // The residual grew past coupling.divergence_residual (1): the coupler stops the run (exit 6).
  EXPECT_EQ(above.codes.at("coupler"), 6) << above.coupler_log;
  EXPECT_NE(above.coupler_log.find("implicit window 0 (t = 0 s, size 0.001 s) diverged"), std::string::npos) << above.coupler_log;
  const auto residual = read_series(above.dir / "coupling_series.h5", "relative_residual");
  ASSERT_EQ(residual.size(), 1u);
  EXPECT_GT(residual[0], 1.0);  // it grew, it did not merely stall
}

// ---------------------------------------------------------------- acoustic piston
// rho 1000, c 10 m/s, 100 cells over 0.1 m, CFL 0.5 (the limits are in mu, whatever the CFL; 0.5
// keeps c dt / dx <= 1 safe from rounding): dt = 5e-5 s; m'' = rho c dt / mu; 100 Pa drive.
Outcome acoustic(const std::string& name, const std::string& scheme, double mu, int windows) {
  const double mass = 1000.0 * 10.0 * 5e-5 / mu;
  return run(name, windows * 5e-5, scheme + " window_size: 5e-5 relative_tolerance: 1e-12 absolute_tolerance: 0 max_iterations: 200 relaxation_factor: 0.1",
             {"--model", "acoustic", "--density", "1000", "--sound-speed", "10", "--column-length", "0.1", "--cells", "100",
              "--area", "1"},
             {"--model", "piston", "--mass", format(mass), "--external-force", "100", "--initial-acceleration",
              format(100.0 / mass), "--area", "1"});
}
constexpr double kTerminalVelocity = 100.0 / (1000.0 * 10.0);  // p / (rho c)
constexpr double kSerialLimit = 2.0;
const double kParallelLimit = 2.0 * (std::sqrt(2.0) - 1.0);

TEST(ModelProblemsThroughCoupler, AcousticPistonSerialExplicitStableBelowMuTwoDivergesAbove) {
  const auto stable = acoustic("mp-serial-stable", "scheme: SERIAL_EXPLICIT", 0.97 * kSerialLimit, 3000);
  ASSERT_TRUE(all_ok(stable)) << stable.coupler_log;
  EXPECT_NEAR(value_after(stable.solid_log, "final u = [-+0-9.eE]+ m, v"), kTerminalVelocity, 1e-6 * kTerminalVelocity);
  const auto unstable = acoustic("mp-serial-unstable", "scheme: SERIAL_EXPLICIT", 1.03 * kSerialLimit, 3000);
  EXPECT_NE(unstable.codes.at("solid"), 0);
  EXPECT_TRUE(stopped_as_runaway(unstable)) << unstable.coupler_log;
  EXPECT_TRUE(named_added_mass(unstable)) << unstable.coupler_log;
  std::printf("%s\n", unstable.coupler_log.substr(unstable.coupler_log.find("error coupler:")).c_str());
}

// Just beyond the limit the mode grows slowly, |z|^2 = mu / 2 per window: at mu = 2.02 the
// piston does not reach the 20 m/s speed bound in 1,200 windows (60 ms). The slow-runaway watch
// (coupling.runaway_oscillation_speed, 0.5 m/s) stops it; switched off, the run ends "fine".
TEST(ModelProblemsThroughCoupler, AcousticPistonSlowRunawayIsStoppedBelowTheSpeedBound) {
  const double mu = 1.01 * kSerialLimit;
  const auto watched = acoustic("mp-serial-slow", "scheme: SERIAL_EXPLICIT", mu, 1200);
  EXPECT_EQ(watched.codes.at("coupler"), 6) << watched.coupler_log;
  EXPECT_NE(watched.codes.at("solid"), 0);
  EXPECT_TRUE(stopped_as_runaway(watched)) << watched.coupler_log;
  EXPECT_NE(watched.coupler_log.find("jumps in velocity from window to window"), std::string::npos) << watched.coupler_log;
  std::smatch speed;
  ASSERT_TRUE(std::regex_search(watched.coupler_log, speed, std::regex(R"(now at ([-+0-9.eE]+) m/s)")));
  EXPECT_LT(std::stod(speed[1].str()), 1.0) << watched.coupler_log;  // far below the 20 m/s speed bound
  EXPECT_TRUE(named_added_mass(watched)) << watched.coupler_log;
  std::printf("%s\n", watched.coupler_log.substr(watched.coupler_log.find("error coupler:")).c_str());
  // The blocks grew as the analysis says: (mu / 2)^(16 / 2) per block of 16 windows.
  const auto oscillation = read_series(watched.dir / "coupling_series.h5", "interface_oscillation");
  std::vector<double> blocks;
  for (std::size_t k = 1; k < oscillation.size(); ++k) {
    if (oscillation[k] != oscillation[k - 1]) blocks.push_back(oscillation[k]);
  }
  ASSERT_GE(blocks.size(), 10u);
  const double growth = std::pow(blocks.back() / blocks[blocks.size() - 9], 1.0 / 8.0);
  EXPECT_NEAR(growth, std::pow(mu / 2.0, 8.0), 0.002) << "last block " << blocks.back();
  EXPECT_GE(blocks.back(), 0.5);
  EXPECT_LT(blocks[blocks.size() - 2], 0.5);

  // Unwatched, the same run ends with exit code 0 while the mode has grown on tenfold: the gap.
  const auto unwatched = acoustic("mp-serial-slow-off", "scheme: SERIAL_EXPLICIT runaway_oscillation_speed: 0", mu, 1200);
  EXPECT_TRUE(all_ok(unwatched)) << unwatched.coupler_log;
  EXPECT_GT(read_series(unwatched.dir / "coupling_series.h5", "interface_oscillation").back(), 10.0 * blocks.back());
}

// The fluid moved with the solid's mean velocity over the previous window instead of its velocity
// at the window's start (coupling.explicit_motion_velocity): one more half window of lag, a lower
// serial limit. With the trapezoidal piston (docs/coupling-numerics.md (b)), A = dt a and s the
// velocity sent: A_{n+1} = -mu s_n, v_{n+1} = v_n + (A_n + A_{n+1}) / 2, s_{n+1} = (v_n + v_{n+1}) / 2;
// the spectral radius of that map reaches 1 at mu = 4/3 (the window's velocity: mu = 2).
TEST(ModelProblemsThroughCoupler, AcousticPistonSerialExplicitWithTheMeanVelocityHasTheLimitMuFourThirds) {
  const std::string scheme = "scheme: SERIAL_EXPLICIT explicit_motion_velocity: PREVIOUS_WINDOW_MEAN";
  const double limit = 4.0 / 3.0;
  const auto stable = acoustic("mp-serial-mean-stable", scheme, 0.97 * limit, 3000);
  ASSERT_TRUE(all_ok(stable)) << stable.coupler_log;
  EXPECT_NEAR(value_after(stable.solid_log, "final u = [-+0-9.eE]+ m, v"), kTerminalVelocity, 1e-6 * kTerminalVelocity);
  const auto unstable = acoustic("mp-serial-mean-unstable", scheme, 1.03 * limit, 3000);
  EXPECT_TRUE(stopped_as_runaway(unstable)) << unstable.coupler_log;
}

TEST(ModelProblemsThroughCoupler, AcousticPistonParallelExplicitFailsEarlier) {
  const auto stable = acoustic("mp-parallel-stable", "scheme: PARALLEL_EXPLICIT", 0.97 * kParallelLimit, 4000);
  ASSERT_TRUE(all_ok(stable)) << stable.coupler_log;
  EXPECT_NEAR(value_after(stable.solid_log, "final u = [-+0-9.eE]+ m, v"), kTerminalVelocity, 1e-6 * kTerminalVelocity);
  const auto unstable = acoustic("mp-parallel-unstable", "scheme: PARALLEL_EXPLICIT", 1.03 * kParallelLimit, 4000);
  EXPECT_TRUE(stopped_as_runaway(unstable)) << unstable.coupler_log;
  // mu = 1.5: serial explicit is fine, parallel explicit is not.
  EXPECT_TRUE(stopped_as_runaway(acoustic("mp-parallel-1.5", "scheme: PARALLEL_EXPLICIT", 1.5, 4000)));
  EXPECT_TRUE(all_ok(acoustic("mp-serial-1.5", "scheme: SERIAL_EXPLICIT", 1.5, 4000)));
}

TEST(ModelProblemsThroughCoupler, AcousticPistonIqnIlsConvergesBeyondBothExplicitLimits) {
  for (const double mu : {2.5, 10.0}) {
    const auto implicit = acoustic("mp-iqn-" + std::to_string(static_cast<int>(mu)), "scheme: SERIAL_IMPLICIT acceleration: IQN_ILS", mu, 1500);
    ASSERT_TRUE(all_ok(implicit)) << implicit.coupler_log;
    EXPECT_NEAR(value_after(implicit.solid_log, "final u = [-+0-9.eE]+ m, v"), kTerminalVelocity, 1e-6 * kTerminalVelocity)
        << "mu " << mu;
    const auto iterations = read_series(implicit.dir / "coupling_series.h5", "iterations");
    EXPECT_LE(*std::max_element(iterations.begin(), iterations.end()), 4.0) << "mu " << mu;  // as in-process
  }
}

// ---------------------------------------------------------------- nonlinear fixed point
TEST(ModelProblemsThroughCoupler, NonlinearFixedPointIqnIlsFindsTheRootPlainIterationDoesNot) {
  const std::string common = "scheme: SERIAL_IMPLICIT window_size: 1 relative_tolerance: 1e-12 absolute_tolerance: 0 max_iterations: 60 ";
  const auto iqn = run("mp-fixed-iqn", 1.0, common + "acceleration: IQN_ILS relaxation_factor: 0.1",
                       {"--model", "fixed-point", "--area", "1"}, {"--model", "fixed-point", "--area", "1"});
  ASSERT_TRUE(all_ok(iqn)) << iqn.coupler_log;
  const auto iterations = read_series(iqn.dir / "coupling_series.h5", "iterations");
  ASSERT_EQ(iterations.size(), 1u);
  EXPECT_LE(iterations[0], 20.0);
  const std::regex root(R"(final x = \[([-+0-9.eE]+), ([-+0-9.eE]+), ([-+0-9.eE]+)\])");
  std::smatch match;
  ASSERT_TRUE(std::regex_search(iqn.solid_log, match, root)) << iqn.solid_log;
  EXPECT_NEAR(std::stod(match[1].str()), 0.4, 1e-9);
  EXPECT_NEAR(std::stod(match[2].str()), -0.3, 1e-9);
  EXPECT_NEAR(std::stod(match[3].str()), 0.8, 1e-9);

  const auto plain = run("mp-fixed-plain", 1.0, common + "acceleration: CONSTANT_RELAXATION relaxation_factor: 1",
                         {"--model", "fixed-point", "--area", "1"},
                         {"--model", "fixed-point", "--area", "1", "--divergence-bound", "1e30"});
  EXPECT_NE(plain.coupler_log.find("not converged after 60 iterations"), std::string::npos) << plain.coupler_log;
}

}  // namespace
}  // namespace valvefsi::testing
