// Restarts through the real coupler and the model stand-ins (docs/coupling.md, "Restarts"):
// a run restarted from its own restart data continues bit for bit as the uninterrupted run
// (explicit, and implicit IQN-ILS whose reused columns the coupler carries); only the newest
// restart_keep complete points are kept; bad restart requests stop with a message.

#include <gtest/gtest.h>

#include <fstream>
#include <regex>

#include "coupled_run.hpp"
#include "valvefsi/coupling/restart_file.hpp"

namespace valvefsi::testing {
namespace {

using namespace std::chrono_literals;

struct Outcome {
  std::map<std::string, int> codes;
  std::string solid_log, coupler_log, fluid_log;
  std::filesystem::path dir;
};

// Acoustic piston (mass ratio mu; serial explicit is stable below 2), 5e-5 s windows, 100 Pa drive.
Outcome acoustic_piston(const std::string& name, const std::string& coupling, double end_time,
                        std::vector<std::string> coupler_args = {},
                        const std::string& fluid = "standin_model_fluid", double mu = 1.5) {
  RunSpec spec;
  spec.name = name;
  spec.end_time = end_time;
  spec.coupling =
      coupling +
      " window_size: 5e-5 relative_tolerance: 1e-12 absolute_tolerance: 0 max_iterations: 200";
  spec.fluid = fluid;
  if (fluid == "standin_model_fluid") {
    spec.fluid_args = {"--model",         "acoustic", "--density", "1000", "--sound-speed", "10",
                       "--column-length", "0.1",      "--cells",   "100",  "--area",        "1"};
  }
  spec.solid = "standin_model_solid";
  const double mass = 1000.0 * 10.0 * 5e-5 / mu;
  spec.solid_args = {"--model",
                     "piston",
                     "--mass",
                     std::to_string(mass),
                     "--external-force",
                     "100",
                     "--initial-acceleration",
                     std::to_string(100.0 / mass),
                     "--area",
                     "1"};
  spec.coupler_args = std::move(coupler_args);
  spec.startup_timeout_s = 10.0;  // the refused runs end without the coupler: do not wait long
  CoupledRun run(spec);
  Outcome outcome;
  outcome.codes = run.wait_all(120s);
  outcome.solid_log = run.solid->log_text();
  outcome.coupler_log = run.coupler->log_text();
  if (run.fluid) outcome.fluid_log = run.fluid->log_text();
  outcome.dir = run.dir;
  return outcome;
}

bool all_ok(const Outcome& o) {
  return o.codes.size() == 3 && o.codes.at("coupler") == 0 && o.codes.at("solid") == 0 &&
         o.codes.at("fluid") == 0;
}

std::string final_state(const std::string& solid_log) {
  std::smatch match;
  const std::regex pattern(R"(final u = \S+ m, v = \S+ m/s)");
  if (!std::regex_search(solid_log, match, pattern)) return "no final state in:\n" + solid_log;
  return match.str();
}

// The last `rows` rows of a 1-D or 2-D series dataset.
std::vector<double> tail(const std::filesystem::path& run, const std::string& dataset,
                         std::size_t values) {
  const auto all = read_series(run / "coupling_series.h5", dataset);
  return {all.end() - static_cast<std::ptrdiff_t>(std::min(values, all.size())), all.end()};
}

// Runs to `end_time` writing restart points every `interval`, then again from the point at
// `from` (folder name), and compares the overlap.
void expect_continues_bit_for_bit(const std::string& coupling, const std::string& name, double mu,
                                  double interval, const std::string& from, double end_time,
                                  std::size_t resumed_windows,
                                  std::filesystem::path* whole_dir = nullptr) {
  const auto whole = acoustic_piston(
      name + "-whole",
      coupling + " restart_interval_s: " + std::to_string(interval) + " restart_keep: 3", end_time,
      {}, "standin_model_fluid", mu);
  ASSERT_TRUE(all_ok(whole)) << whole.coupler_log;
  if (whole_dir != nullptr) *whole_dir = whole.dir;
  const auto folder = whole.dir / "restart" / from;
  ASSERT_TRUE(std::filesystem::exists(folder / "COMPLETE")) << whole.coupler_log;
  for (const char* file : {"coupler.restart.h5", "fluid.restart.h5", "solid.restart.h5"})
    EXPECT_TRUE(std::filesystem::exists(folder / file)) << file;

  const auto resumed = acoustic_piston(name + "-resumed", coupling, end_time,
                                       {"--restart", folder.string()}, "standin_model_fluid", mu);
  ASSERT_TRUE(all_ok(resumed)) << resumed.coupler_log << resumed.solid_log;
  EXPECT_NE(resumed.coupler_log.find("continuing from"), std::string::npos);
  // Printed with 13 significant digits: the same string. The series: identical doubles.
  EXPECT_EQ(final_state(resumed.solid_log), final_state(whole.solid_log));
  const auto resumed_rows = read_series(resumed.dir / "coupling_series.h5", "time").size();
  EXPECT_EQ(resumed_rows, resumed_windows);
  for (const char* dataset :
       {"time", "force_fluid", "power_solid", "iterations", "window_index", "relative_residual"}) {
    const std::size_t width = std::string(dataset) == "force_fluid" ? 3 : 1;
    EXPECT_EQ(tail(resumed.dir, dataset, width * resumed_rows),
              tail(whole.dir, dataset, width * resumed_rows))
        << dataset;
  }
}

TEST(CouplerRestart, SerialExplicitContinuesBitForBit) {
  // 400 windows, points at 5, 10, 15 ms; resume from 10 ms.
  expect_continues_bit_for_bit("scheme: SERIAL_EXPLICIT", "restart-explicit", 1.5, 0.005,
                               "t_0.010000000", 0.02, 200);
}

// The previous window's mean velocity is carried in the coupler's restart file.
TEST(CouplerRestart, SerialExplicitWithThePreviousWindowsMeanVelocityContinuesBitForBit) {
  expect_continues_bit_for_bit("scheme: SERIAL_EXPLICIT explicit_motion_velocity: PREVIOUS_WINDOW_MEAN",
                               "restart-explicit-mean", 1.0, 0.005, "t_0.010000000", 0.02, 200);
}

TEST(CouplerRestart, ImplicitIqnIlsContinuesBitForBitWithItsReusedColumns) {
  // mu = 10 (beyond both explicit limits): IQN-ILS still iterates in the transient and carries
  // columns from past windows; 80 windows, points at 1, 2, 3 ms; resume from 1 ms.
  const std::string coupling =
      "scheme: SERIAL_IMPLICIT acceleration: IQN_ILS iqn_reused_windows: 8 relaxation_factor: 0.1";
  std::filesystem::path whole;
  expect_continues_bit_for_bit(coupling, "restart-iqn", 10.0, 0.001, "t_0.001000000", 0.004, 60,
                               &whole);
  // The test means something only if columns were carried across the restart point.
  ASSERT_FALSE(whole.empty());
  EXPECT_GT(coupling::RestartReader(whole / "restart" / "t_0.001000000" / "coupler.restart.h5")
                .integer("acceleration_vector_count"),
            0);
}

TEST(CouplerRestart, KeepsTheNewestCompletePointsAndNamesTheLatest) {
  const auto run = acoustic_piston(
      "restart-keep", "scheme: SERIAL_EXPLICIT restart_interval_s: 0.004 restart_keep: 2", 0.02);
  ASSERT_TRUE(all_ok(run)) << run.coupler_log;
  std::vector<std::string> folders;
  for (const auto& entry : std::filesystem::directory_iterator(run.dir / "restart"))
    if (entry.is_directory()) folders.push_back(entry.path().filename().string());
  std::sort(folders.begin(), folders.end());
  // Points at 4, 8, 12, 16 ms: the last two stay.
  EXPECT_EQ(folders, (std::vector<std::string>{"t_0.012000000", "t_0.016000000"}));
  std::ifstream latest(run.dir / "restart" / "LATEST");
  std::string name;
  latest >> name;
  EXPECT_EQ(name, "t_0.016000000");
}

TEST(CouplerRestart, RefusesAMissingFolderAndAParticipantThatCannotRestart) {
  const auto missing = acoustic_piston("restart-missing", "scheme: SERIAL_EXPLICIT", 0.01,
                                       {"--restart", "/nonexistent/restart"});
  EXPECT_NE(missing.codes.at("coupler"), 0);
  EXPECT_NE(missing.coupler_log.find("--restart /nonexistent/restart: no such folder"),
            std::string::npos)
      << missing.coupler_log;

  const auto unable =
      acoustic_piston("restart-unable", "scheme: SERIAL_EXPLICIT restart_interval_s: 0.005", 0.01,
                      {}, "standin_fluid_pressure");
  EXPECT_NE(unable.codes.at("coupler"), 0);
  EXPECT_NE(unable.coupler_log.find("has no 'restart' capability"), std::string::npos)
      << unable.coupler_log;
}

}  // namespace
}  // namespace valvefsi::testing
