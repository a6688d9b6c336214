// scripts/run_case.py with real programs: the stand-in case end to end, a failing participant
// (the others are stopped, the launcher returns the failing code), a frozen participant, the
// launcher itself interrupted, a bad case, and --fe-only. After each, no process of the run
// may remain.

#include <gtest/gtest.h>
#include <signal.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <thread>

#include "coupled_run.hpp"
#include "process_harness.hpp"

namespace valvefsi::testing {
namespace {

using namespace std::chrono_literals;

// Process ids whose command line mentions `needle` (our run folder), ourselves excluded.
std::vector<pid_t> processes_mentioning(const std::string& needle) {
  std::vector<pid_t> found;
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const auto name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream in(entry.path() / "cmdline");
    std::stringstream text;
    text << in.rdbuf();
    std::string cmdline = text.str();
    for (auto& c : cmdline) if (c == '\0') c = ' ';
    if (cmdline.find(needle) != std::string::npos && std::stoi(name) != ::getpid()) found.push_back(std::stoi(name));
  }
  return found;
}

std::unique_ptr<ChildProcess> launch(const std::filesystem::path& case_file, const std::filesystem::path& output,
                                     std::vector<std::string> extra = {}) {
  std::vector<std::string> argv = {"/usr/bin/python3", VALVEFSI_TEST_SOURCE_DIR "/scripts/run_case.py", case_file.string(),
                                   "--output", output.string(), "--build-dir", VALVEFSI_TEST_BINARY_DIR, "--grace", "2"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  return std::make_unique<ChildProcess>(argv, output.parent_path() / (output.filename().string() + "-launcher.log"));
}

std::filesystem::path write_case(const std::filesystem::path& dir, const std::string& fluid_args,
                                 const std::string& solid_args, double end_time = 100.0) {
  const auto file = dir / "case.textproto";
  write_file(file, "run { end_time: " + std::to_string(end_time) +
                       " }\ncoupling {\n  heartbeat_interval_s: 0.1 peer_timeout_s: 1\n"
                       "  fluid_executable: \"standin_fluid_pressure\" fluid_arguments: [" + fluid_args +
                       "]\n  solid_executable: \"standin_solid_plate\" solid_arguments: [" + solid_args + "]\n}\n");
  return file;
}

void expect_nothing_left(const std::filesystem::path& output) {
  std::this_thread::sleep_for(100ms);
  EXPECT_TRUE(processes_mentioning(output.string()).empty()) << "processes of the run remain";
}

TEST(Launcher, StandinCaseRunsEndToEndWithPrefixedLogs) {
  const auto dir = fresh_directory("launch-ok");
  const auto output = dir / "run";
  auto launcher = launch(VALVEFSI_TEST_SOURCE_DIR "/cases/standin-plate.textproto", output);
  ASSERT_EQ(launcher->wait_for_exit(60s), std::optional<int>(0)) << launcher->log_text();
  const auto text = launcher->log_text();
  EXPECT_NE(text.find("[solid] "), std::string::npos);
  EXPECT_NE(text.find("[fluid] "), std::string::npos);
  EXPECT_NE(text.find("[coupler] "), std::string::npos);
  // The case's promise: z(0.05 s) = 2e-3 (1 - cos 5).
  std::ifstream solid_log(output / "solid.log");
  std::stringstream solid_text;
  solid_text << solid_log.rdbuf();
  EXPECT_NEAR(final_plate_z(solid_text.str()), 2e-3 * (1.0 - std::cos(5.0)), 1e-12);
  EXPECT_EQ(read_series(output / "coupling_series.h5", "time").size(), 50u);
  EXPECT_FALSE(std::filesystem::exists(output / "coupler.ipc"));  // the socket file is cleaned up
  expect_nothing_left(output);
}

TEST(Launcher, FluidRanksStartTheFluidUnderMpirun) {
  const auto dir = fresh_directory("launch-mpi");
  const auto output = dir / "run";
  auto launcher = launch(VALVEFSI_TEST_SOURCE_DIR "/cases/standin-plate.textproto", output, {"--fluid-ranks", "2"});
  ASSERT_EQ(launcher->wait_for_exit(60s), std::optional<int>(0)) << launcher->log_text();
  std::ifstream fluid_log(output / "fluid.log");
  std::stringstream fluid_text;
  fluid_text << fluid_log.rdbuf();
  EXPECT_NE(fluid_text.str().find("MPI rank 1 of 2: idle"), std::string::npos) << fluid_text.str();
  // The coupled result is the same as with one fluid process.
  std::ifstream solid_log(output / "solid.log");
  std::stringstream solid_text;
  solid_text << solid_log.rdbuf();
  EXPECT_NEAR(final_plate_z(solid_text.str()), 2e-3 * (1.0 - std::cos(5.0)), 1e-12);
  expect_nothing_left(output);
}

TEST(Launcher, FailingParticipantStopsTheOthersAndItsCodeIsReturned) {
  const auto dir = fresh_directory("launch-fail");
  const auto output = dir / "run";
  auto launcher = launch(write_case(dir, "\"--step-seconds\", \"0.02\"", "\"--exit-at-window\", \"5\""), output);
  const auto code = launcher->wait_for_exit(30s);
  ASSERT_TRUE(code.has_value()) << launcher->log_text();
  EXPECT_EQ(*code, 7) << launcher->log_text();
  EXPECT_NE(launcher->log_text().find("solid failed with exit code 7"), std::string::npos) << launcher->log_text();
  expect_nothing_left(output);
}

// The coupler relays the fluid's abort (exit 5, "aborted by a peer") and may exit before the
// fluid does; the launcher must still name the fluid, the origin, and return its code.
TEST(Launcher, TheParticipantThatFailedIsNamedNotTheOneRelayingItsAbort) {
  const auto dir = fresh_directory("launch-relay");
  const auto output = dir / "run";
  auto launcher = launch(write_case(dir, "\"--step-seconds\", \"0.02\", \"--fail-at-window\", \"5\"", "\"--step-seconds\", \"0.02\""),
                         output);
  const auto code = launcher->wait_for_exit(30s);
  ASSERT_TRUE(code.has_value()) << launcher->log_text();
  EXPECT_EQ(*code, 2) << launcher->log_text();
  EXPECT_NE(launcher->log_text().find("fluid failed with exit code 2"), std::string::npos) << launcher->log_text();
  EXPECT_EQ(launcher->log_text().find("coupler failed"), std::string::npos) << launcher->log_text();
  EXPECT_NE(launcher->log_text().find("deliberate failure at window 5"), std::string::npos) << launcher->log_text();
  expect_nothing_left(output);
}

TEST(Launcher, FrozenParticipantEndsTheRunAndIsStopped) {
  const auto dir = fresh_directory("launch-frozen");
  const auto output = dir / "run";
  auto launcher = launch(write_case(dir, "\"--step-seconds\", \"0.02\"", ""), output);
  std::vector<pid_t> fluid;
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (fluid.empty() && std::chrono::steady_clock::now() < deadline) {
    for (pid_t pid : processes_mentioning(output.string())) {
      std::ifstream in("/proc/" + std::to_string(pid) + "/cmdline");
      std::string cmdline((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      if (cmdline.find("standin_fluid_pressure") != std::string::npos) fluid.push_back(pid);
    }
    std::this_thread::sleep_for(50ms);
  }
  ASSERT_EQ(fluid.size(), 1u);
  // Freeze it mid-run (frozen before its first word it would count as not yet started).
  auto coupler_log = [&] {
    std::ifstream in(output / "coupler.log");
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  while (coupler_log().find("mapped") == std::string::npos && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(20ms);
  }
  std::this_thread::sleep_for(300ms);
  ::kill(fluid[0], SIGSTOP);
  const auto code = launcher->wait_for_exit(15s);
  ASSERT_TRUE(code.has_value()) << launcher->log_text();
  EXPECT_NE(*code, 0);
  EXPECT_NE(launcher->log_text().find("participant 'fluid' has been silent"), std::string::npos) << launcher->log_text();
  expect_nothing_left(output);
}

TEST(Launcher, SigtermToTheLauncherStopsEverything) {
  const auto dir = fresh_directory("launch-term");
  const auto output = dir / "run";
  auto launcher = launch(write_case(dir, "\"--step-seconds\", \"0.02\"", ""), output);
  std::this_thread::sleep_for(1500ms);
  ASSERT_TRUE(launcher->running()) << launcher->log_text();
  ::kill(launcher->pid(), SIGTERM);
  EXPECT_EQ(launcher->wait_for_exit(15s), std::optional<int>(128 + SIGTERM)) << launcher->log_text();
  expect_nothing_left(output);
}

TEST(Launcher, BadCaseIsReportedWithFileFieldAndLimitBeforeAnythingStarts) {
  const auto dir = fresh_directory("launch-bad");
  const auto file = dir / "bad.textproto";
  write_file(file, "run { end_time: 1 }\ncoupling {\n  peer_timeout_s: -2\n}\n");
  auto launcher = launch(file, dir / "run");
  const auto code = launcher->wait_for_exit(20s);
  ASSERT_TRUE(code.has_value());
  EXPECT_NE(*code, 0);
  const auto text = launcher->log_text();
  EXPECT_NE(text.find("bad.textproto:3"), std::string::npos) << text;
  EXPECT_NE(text.find("coupling.peer_timeout_s"), std::string::npos) << text;
}

TEST(Launcher, FeOnlyRunsTheSolidAlone) {
  const auto dir = fresh_directory("launch-fe");
  const auto output = dir / "run";
  auto launcher = launch(VALVEFSI_TEST_SOURCE_DIR "/cases/standin-plate.textproto", output, {"--fe-only"});
  ASSERT_EQ(launcher->wait_for_exit(30s), std::optional<int>(0)) << launcher->log_text();
  EXPECT_NE(launcher->log_text().find("[solid] "), std::string::npos);
  EXPECT_EQ(launcher->log_text().find("[coupler] "), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(output / "fluid.log"));
}

}  // namespace
}  // namespace valvefsi::testing
