// fluid_sph as the fluid participant, through the real coupler, against a 2D stand-in solid
// (one rigid leaflet, tests/fluid_sph/standin_solid_leaflet_2d.cpp) built into a partition
// of a tank: water 0.1 m deep on its left, 0.05 m on its right. The leaflet then carries the
// hydrostatic difference F_x = rho g (hL^2 - hR^2) / 2 per metre of depth, the coupler's
// force series must show the fluid's total equal to the solid's, and a solid that dies
// mid-run must stop the fluid with a message and a nonzero exit. Under the implicit scheme the
// fluid repeats every window from its checkpoint and must land on the explicit run's forces.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <regex>

#include "coupled_run.hpp"
#include "process_harness.hpp"

namespace {

using valvefsi::testing::ChildProcess;

constexpr double kRho = 1000.0, kG = 9.81, kLeft = 0.1, kRight = 0.05;

struct Processes {
  std::filesystem::path dir;
  std::unique_ptr<ChildProcess> coupler, solid, fluid;
};

Processes start(const std::string& name, double end_time, const std::vector<std::string>& solid_extra,
                const std::string& scheme = "scheme: SERIAL_EXPLICIT", const std::string& fluid_extra = "") {
  Processes r;
  r.dir = valvefsi::testing::fresh_directory(name);
  const auto case_file = r.dir / "case.textproto";
  valvefsi::testing::write_file(case_file, fmt::format(R"(run {{ end_time: {} output_dir: "{}" dimension: 2 series_interval: 0.01 }}
fluid {{
  particle_spacing: 0.005
  density: 1000
  dynamic_viscosity: 0.001
  sound_speed: 20
  artificial_viscosity: 0.02
  gravity: [0, -9.81]
  domain_lower: [-0.03, -0.03]
  domain_upper: [0.13, 0.3]
  fluid_blocks {{ box {{ lower: [0, 0] upper: [0.05, {}] }} }}
  fluid_blocks {{ box {{ lower: [0.05, 0] upper: [0.1, {}] }} }}
  walls {{ container {{ lower: [0, 0] upper: [0.1, 10] }} }}
  thin_walls {{ }}
  {}
}}
coupling {{
  {}
  window_size: 1e-4
  mapping: NEAREST_PROJECTION
  endpoint: "ipc://{}/c.ipc"
  heartbeat_interval_s: 0.1
  peer_timeout_s: 3
  startup_timeout_s: 60
}}
)",
                                                       end_time, r.dir.string(), kLeft, kRight, fluid_extra, scheme, r.dir.string()));
  const std::vector<std::string> common = {"--case", case_file.string(), "--output", r.dir.string()};
  auto with = [&](std::vector<std::string> argv, const std::vector<std::string>& extra) {
    argv.insert(argv.end(), extra.begin(), extra.end());
    argv.insert(argv.end(), common.begin(), common.end());
    return argv;
  };
  r.coupler = std::make_unique<ChildProcess>(with({valvefsi::testing::coupler_exe()}, {}), r.dir / "coupler.log");
  // The leaflet stands in the partition x = 0.05 from inside the bottom wall to above the water.
  std::vector<std::string> solid_args = {"--x", "0.05", "--y0", "-0.01", "--y1", "0.14", "--nodes", "31", "--average-from", "0.1"};
  solid_args.insert(solid_args.end(), solid_extra.begin(), solid_extra.end());
  r.solid = std::make_unique<ChildProcess>(with({VALVEFSI_TEST_LEAFLET_SOLID}, solid_args), r.dir / "solid.log");
  // The fluid learns that it is coupled from the launcher's environment variable.
  r.fluid = std::make_unique<ChildProcess>(with({VALVEFSI_TEST_FLUID_SPH}, {"--threads", "1"}), r.dir / "fluid.log",
                                           std::vector<std::string>{"VALVEFSI_COUPLER_ENDPOINT=ipc://" + r.dir.string() + "/c.ipc"});
  return r;
}

double mean_received_x(const std::string& solid_log) {
  static const std::regex pattern(R"(mean received force = ([-+0-9.eE]+) )");
  std::smatch match;
  if (!std::regex_search(solid_log, match, pattern)) throw std::runtime_error("no mean force in the solid's log:\n" + solid_log);
  return std::stod(match[1].str());
}

TEST(FluidParticipant, LeafletCarriesHydrostaticDifferenceThroughTheCoupler) {
  Processes r = start("fluid_participant_hydrostatic", 0.3, {});
  const auto fluid_code = r.fluid->wait_for_exit(std::chrono::seconds(240));
  const auto solid_code = r.solid->wait_for_exit(std::chrono::seconds(20));
  const auto coupler_code = r.coupler->wait_for_exit(std::chrono::seconds(20));
  ASSERT_TRUE(fluid_code && solid_code && coupler_code) << r.fluid->log_text();
  EXPECT_EQ(*fluid_code, 0) << r.fluid->log_text();
  EXPECT_EQ(*solid_code, 0) << r.solid->log_text();
  EXPECT_EQ(*coupler_code, 0) << r.coupler->log_text();

  // Conservation through the coupler: per window the solid receives the fluid's total force.
  const auto series = r.dir / "coupling_series.h5";
  const auto fluid_force = valvefsi::testing::read_series(series, "force_fluid");
  const auto solid_force = valvefsi::testing::read_series(series, "force_solid");
  ASSERT_EQ(fluid_force.size(), solid_force.size());
  ASSERT_GE(fluid_force.size(), 3u * 2900u);
  double worst = 0, scale = 0;
  for (std::size_t i = 0; i < fluid_force.size(); ++i) {
    worst = std::max(worst, std::abs(fluid_force[i] - solid_force[i]));
    scale = std::max(scale, std::abs(fluid_force[i]));
  }
  EXPECT_LT(worst, 1e-9 * scale);

  // Physics: the water pushes the leaflet towards the shallow side with the hydrostatic
  // difference (per metre of depth), window average over 0.1-0.3 s.
  const double expected = 0.5 * kRho * kG * (kLeft * kLeft - kRight * kRight);
  const double received = mean_received_x(r.solid->log_text());
  std::printf("leaflet force: %.3f N/m received, %.3f N/m hydrostatic (%+.2f %%)\n", received, expected,
              100.0 * (received / expected - 1.0));
  EXPECT_NEAR(received, expected, 0.1 * expected);
  EXPECT_NE(r.fluid->log_text().find("0 leaks"), std::string::npos) << r.fluid->log_text();
}

// The leaflet oscillates (prescribed, load-independent), so the implicit scheme needs more
// than one pass per window and the fluid restarts from its checkpoint; the converged run must
// match the explicit one up to the explicit scheme's one-window lag of the motion.
TEST(FluidParticipant, ImplicitSchemeRepeatsWindowsFromTheCheckpoint) {
  const double end = 0.03;
  const std::vector<std::string> oscillate = {"--amplitude", "0.002", "--frequency", "5"};
  Processes explicit_run = start("fluid_participant_explicit", end, oscillate);
  Processes implicit_run = start("fluid_participant_implicit", end, oscillate,
                                 "scheme: SERIAL_IMPLICIT acceleration: AITKEN relaxation_factor: 0.5 "
                                 "relative_tolerance: 1e-6 max_iterations: 20");
  for (Processes* r : {&explicit_run, &implicit_run}) {
    const auto fluid_code = r->fluid->wait_for_exit(std::chrono::seconds(240));
    ASSERT_TRUE(fluid_code) << r->fluid->log_text();
    EXPECT_EQ(*fluid_code, 0) << r->fluid->log_text();
    ASSERT_TRUE(r->coupler->wait_for_exit(std::chrono::seconds(20)));
    ASSERT_TRUE(r->solid->wait_for_exit(std::chrono::seconds(20)));
  }
  static const std::regex repeated(R"(([0-9]+) repeated windows)");
  std::smatch match;
  const std::string log = implicit_run.fluid->log_text();
  ASSERT_TRUE(std::regex_search(log, match, repeated)) << log;
  const int repeats = std::stoi(match[1].str());
  const auto a = valvefsi::testing::read_series(explicit_run.dir / "coupling_series.h5", "force_fluid");
  const auto b = valvefsi::testing::read_series(implicit_run.dir / "coupling_series.h5", "force_fluid");
  ASSERT_EQ(a.size(), b.size());
  EXPECT_GE(repeats, static_cast<int>(a.size() / 3));  // every window at least once more
  double mean_difference = 0, scale = 0;
  for (std::size_t i = 0; i < a.size(); i += 3) {
    mean_difference += std::abs(a[i] - b[i]) / static_cast<double>(a.size() / 3);
    scale = std::max(scale, std::abs(a[i]));
  }
  std::printf("implicit vs explicit: %zu windows, %d repeated, mean |dF_x| %.3e of %.3e N/m\n", a.size() / 3, repeats,
              mean_difference, scale);
  EXPECT_LT(mean_difference, 0.01 * scale);
}

// fluid.fit_coupling_window_to_steps: the case's 1e-4 s window holds 1.8 stable steps, so the
// fluid takes two steps per window; fitted, it proposes one whole (0.97-shrunk) step per window
// and takes exactly one step per window: 20 % fewer steps.
TEST(FluidParticipant, FittedWindowsHoldWholeFluidSteps) {
  const double end = 0.02;
  Processes plain = start("fluid_participant_plain_windows", end, {});
  Processes fitted = start("fluid_participant_fitted_windows", end, {}, "scheme: SERIAL_EXPLICIT",
                           "fit_coupling_window_to_steps: true");
  static const std::regex done(R"(in ([0-9]+) steps)");
  struct Counts {
    long steps = 0, windows = 0;
    double last_window = 0;
  };
  auto counts = [&](Processes& r) {
    const auto fluid_code = r.fluid->wait_for_exit(std::chrono::seconds(240));
    EXPECT_TRUE(fluid_code && *fluid_code == 0) << r.fluid->log_text();
    EXPECT_TRUE(r.coupler->wait_for_exit(std::chrono::seconds(20)));
    EXPECT_TRUE(r.solid->wait_for_exit(std::chrono::seconds(20)));
    Counts n;
    std::smatch match;
    const std::string log = r.fluid->log_text();
    if (std::regex_search(log, match, done)) n.steps = std::stol(match[1].str());
    const auto index = valvefsi::testing::read_series(r.dir / "coupling_series.h5", "window_index");
    const auto size = valvefsi::testing::read_series(r.dir / "coupling_series.h5", "window_size");
    if (!index.empty()) n.windows = static_cast<long>(index.back()) + 1;
    if (!size.empty()) n.last_window = size.back();
    return n;
  };
  const Counts a = counts(plain), b = counts(fitted);
  std::printf("plain: %ld steps in %ld windows; fitted: %ld steps in %ld windows (last %.4g s)\n", a.steps, a.windows,
              b.steps, b.windows, b.last_window);
  EXPECT_EQ(a.windows, 200);  // 0.02 s of 1e-4 s windows
  EXPECT_EQ(a.steps, 2 * a.windows);
  EXPECT_LT(b.last_window, 1e-4);
  EXPECT_GT(b.windows, a.windows);
  EXPECT_EQ(b.steps, b.windows + 1);  // the first window, before any proposal, is the case's: 2 steps
  EXPECT_LT(b.steps, a.steps * 85 / 100);
}

TEST(FluidParticipant, DeadSolidStopsTheFluidWithAMessage) {
  Processes r = start("fluid_participant_dead_solid", 0.3, {"--exit-at-window", "30"});
  const auto solid_code = r.solid->wait_for_exit(std::chrono::seconds(120));
  const auto fluid_code = r.fluid->wait_for_exit(std::chrono::seconds(60));
  const auto coupler_code = r.coupler->wait_for_exit(std::chrono::seconds(20));
  ASSERT_TRUE(solid_code && fluid_code && coupler_code) << r.fluid->log_text();
  EXPECT_EQ(*solid_code, 7);
  EXPECT_NE(*fluid_code, 0) << r.fluid->log_text();
  EXPECT_NE(*coupler_code, 0);
  const std::string log = r.fluid->log_text();
  EXPECT_NE(log.find("solid"), std::string::npos) << log;
  std::printf("fluid exit code %d; its last words:\n%s\n", *fluid_code, log.substr(log.size() > 400 ? log.size() - 400 : 0).c_str());
}

// The same program alone: --standalone wins over the launcher's variable, the run needs no
// coupler, and the probe series holds one row per series_interval.
TEST(FluidProgram, StandaloneRunWritesItsSeries) {
  const auto dir = valvefsi::testing::fresh_directory("fluid_standalone");
  const auto case_file = dir / "case.textproto";
  valvefsi::testing::write_file(case_file, fmt::format(R"(run {{ end_time: 0.05 output_dir: "{}" dimension: 2 series_interval: 0.01 }}
fluid {{
  particle_spacing: 0.01
  density: 1000
  sound_speed: 20
  artificial_viscosity: 0.02
  gravity: [0, -9.81]
  domain_lower: [-0.05, -0.05]
  domain_upper: [0.15, 0.3]
  fluid_blocks {{ box {{ lower: [0, 0] upper: [0.1, 0.1] }} }}
  walls {{ container {{ lower: [0, 0] upper: [0.1, 10] }} }}
  probes {{ pressure_points {{ name: "bottom" position: [0.05, 0.02] }} }}
}}
)",
                                                       dir.string()));
  ChildProcess fluid({VALVEFSI_TEST_FLUID_SPH, "--case", case_file.string(), "--output", dir.string(), "--standalone",
                      "--threads", "1"},
                     dir / "fluid.log", {"VALVEFSI_COUPLER_ENDPOINT=ipc://" + dir.string() + "/nobody.ipc"});
  const auto code = fluid.wait_for_exit(std::chrono::seconds(120));
  ASSERT_TRUE(code) << fluid.log_text();
  EXPECT_EQ(*code, 0) << fluid.log_text();
  const auto time = valvefsi::testing::read_series(dir / "fluid_probes.h5", "time");
  ASSERT_EQ(time.size(), 6u);
  for (std::size_t k = 0; k < time.size(); ++k) EXPECT_NEAR(time[k], 0.01 * static_cast<double>(k), 1e-12);
  // Hydrostatic at the probe (0.08 m under the surface) within 10 % once the start has settled.
  const auto pressure = valvefsi::testing::read_series(dir / "fluid_probes.h5", "pressure/bottom");
  EXPECT_NEAR(pressure.back(), 1000 * 9.81 * 0.08, 0.1 * 1000 * 9.81 * 0.08);
}

// A run that stops on a collapsing time step (here forced by a guard of 0.97 of the step at
// rest: the collapsing column soon moves faster than 3 % of c0) exits non-zero, says where,
// and leaves its probe series and a snapshot of the state it stopped in.
TEST(FluidProgram, TimeStepCollapseLeavesProbesAndLastState) {
  const auto dir = valvefsi::testing::fresh_directory("fluid_collapse");
  const auto case_file = dir / "case.textproto";
  valvefsi::testing::write_file(case_file, fmt::format(R"(run {{ end_time: 0.5 output_dir: "{}" dimension: 2 series_interval: 0.01 snapshot_interval: 0.1 }}
fluid {{
  particle_spacing: 0.01
  density: 1000
  sound_speed: 20
  artificial_viscosity: 0.02
  gravity: [0, -9.81]
  min_time_step_ratio: 0.97
  domain_lower: [-0.05, -0.05]
  domain_upper: [0.35, 0.3]
  fluid_blocks {{ box {{ lower: [0, 0] upper: [0.1, 0.1] }} }}
  walls {{ container {{ lower: [0, 0] upper: [0.3, 10] }} }}
  probes {{ pressure_points {{ name: "bottom" position: [0.05, 0.02] }} }}
}}
)",
                                                       dir.string()));
  ChildProcess fluid({VALVEFSI_TEST_FLUID_SPH, "--case", case_file.string(), "--output", dir.string(), "--standalone",
                      "--threads", "1"},
                     dir / "fluid.log");
  const auto code = fluid.wait_for_exit(std::chrono::seconds(120));
  ASSERT_TRUE(code) << fluid.log_text();
  EXPECT_EQ(*code, 1) << fluid.log_text();
  const std::string log = fluid.log_text();
  EXPECT_NE(log.find("time step collapsed"), std::string::npos) << log;
  EXPECT_NE(log.find("set by the acoustic limit"), std::string::npos) << log;
  EXPECT_NE(log.find("largest speed"), std::string::npos) << log;
  const auto time = valvefsi::testing::read_series(dir / "fluid_probes.h5", "time");
  ASSERT_GE(time.size(), 2u);
  // The last row is the state it stopped in (between the regular rows), the rows before it are regular.
  EXPECT_GT(time.back(), time[time.size() - 2]);
  EXPECT_LT(time.back() - time[time.size() - 2], 0.01);
  std::printf("stopped at t = %.6f s after %zu probe rows\n", time.back(), time.size());
  const auto stopped = valvefsi::testing::read_series(dir / "fluid_particles.h5",
                                                      fmt::format("snapshot_{:06d}/pressure", static_cast<int>(time.back() / 0.1) + 1));
  EXPECT_FALSE(stopped.empty());
}

}  // namespace
