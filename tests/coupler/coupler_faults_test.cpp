// Faults with real processes: a participant killed (SIGKILL), frozen (SIGSTOP), exiting
// silently, sending a malformed message, a foreign protocol version, a NaN or a message out of
// order, and the coupler itself killed. In every case each process still alive must exit
// non-zero within a few seconds with a message naming the participant and the cause; the
// harness reaps everything. A long step, on the other hand, must not look like a hang.

#include <gtest/gtest.h>
#include <signal.h>

#include <thread>

#include "coupled_run.hpp"
#include "valvefsi/coupling/transport_errors.hpp"

namespace valvefsi::testing {
namespace {

using namespace std::chrono_literals;
using coupling::kExitAborted;
using coupling::kExitPeerLost;
using coupling::kExitProtocolError;

// Heartbeat 0.1 s, peer timeout 1 s: a lost peer must be noticed within about a second.
RunSpec long_run(const std::string& name) {
  RunSpec spec;
  spec.name = name;
  spec.end_time = 100.0;  // never reached: the fault comes first
  spec.coupling = "window_size: 1e-3";
  spec.heartbeat_interval_s = 0.1;
  spec.peer_timeout_s = 1.0;
  spec.fluid_args = {"--step-seconds", "0.02"};
  spec.solid_args = {"--step-seconds", "0.01"};
  return spec;
}

// Both windows-in-progress and the series file exist once the run is under way.
void wait_until_running(CoupledRun& run) {
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (std::chrono::steady_clock::now() < deadline &&
         run.coupler->log_text().find("mapped") == std::string::npos) {
    std::this_thread::sleep_for(20ms);
  }
  std::this_thread::sleep_for(300ms);  // a few windows
  ASSERT_TRUE(run.coupler->running() && run.solid->running() && run.fluid->running()) << run.coupler->log_text();
}

void expect_exit(ChildProcess& process, int expected, std::chrono::duration<double> within, const std::string& says,
                 const std::string& role) {
  const auto start = std::chrono::steady_clock::now();
  const auto code = process.wait_for_exit(within);
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(code.has_value()) << role << " still running after " << within.count() << " s:\n" << process.log_text();
  if (expected >= 0) {
    EXPECT_EQ(*code, expected) << role << ":\n" << process.log_text();
  }
  EXPECT_NE(*code, 0) << role;
  EXPECT_NE(process.log_text().find(says), std::string::npos)
      << role << " should say \"" << says << "\" (took " << took << " s):\n" << process.log_text();
}

TEST(CouplerFaults, KilledFluidStopsCouplerAndSolidNamingTheFluid) {
  CoupledRun run(long_run("kill-fluid"));
  wait_until_running(run);
  run.fluid->send_signal(SIGKILL);
  expect_exit(*run.coupler, kExitPeerLost, 6s, "participant 'fluid'", "coupler");
  expect_exit(*run.solid, kExitAborted, 6s, "participant 'fluid'", "solid");
}

TEST(CouplerFaults, FrozenFluidIsDeclaredSilentAndEverythingElseStops) {
  CoupledRun run(long_run("stop-fluid"));
  wait_until_running(run);
  run.fluid->send_signal(SIGSTOP);
  expect_exit(*run.coupler, kExitPeerLost, 6s, "participant 'fluid' has been silent", "coupler");
  expect_exit(*run.solid, kExitAborted, 6s, "participant 'fluid' has been silent", "solid");
  // The frozen process is the launcher's to kill (scripts/run_case.py does); here the harness does.
}

TEST(CouplerFaults, FrozenSolidDuringTheFluidsStepIsNoticed) {
  CoupledRun run(long_run("stop-solid"));
  wait_until_running(run);
  run.solid->send_signal(SIGSTOP);
  expect_exit(*run.coupler, kExitPeerLost, 6s, "participant 'solid'", "coupler");
  expect_exit(*run.fluid, kExitAborted, 6s, "participant 'solid'", "fluid");
}

TEST(CouplerFaults, KilledCouplerStopsBothParticipantsEvenMidStep) {
  auto spec = long_run("kill-coupler");
  spec.fluid_args = {"--step-seconds", "3.0"};  // the fluid is inside a long step when it happens
  CoupledRun run(spec);
  wait_until_running(run);
  run.coupler->send_signal(SIGKILL);
  expect_exit(*run.fluid, kExitPeerLost, 6s, "the coupler has been silent", "fluid");
  expect_exit(*run.solid, kExitPeerLost, 6s, "the coupler has been silent", "solid");
}

TEST(CouplerFaults, ParticipantExitingSilentlyIsNamed) {
  auto spec = long_run("exit-solid");
  spec.solid_args = {"--exit-at-window", "5"};
  CoupledRun run(spec);
  expect_exit(*run.solid, 7, 20s, "", "solid");
  expect_exit(*run.coupler, kExitPeerLost, 6s, "participant 'solid'", "coupler");
  expect_exit(*run.fluid, kExitAborted, 6s, "participant 'solid'", "fluid");
}

TEST(CouplerFaults, MalformedMessageEndsTheRunNamingTheSender) {
  auto spec = long_run("malformed");
  spec.fluid = "standin_rogue_fluid";
  spec.fluid_args = {"--misbehave", "malformed"};
  CoupledRun run(spec);
  expect_exit(*run.coupler, kExitProtocolError, 20s, "participant 'fluid' sent a malformed message", "coupler");
  expect_exit(*run.solid, kExitAborted, 6s, "malformed", "solid");
  expect_exit(*run.fluid, kExitAborted, 6s, "the coupler aborted the run", "fluid");
}

TEST(CouplerFaults, ProtocolVersionMismatchNamesBothVersions) {
  auto spec = long_run("version");
  spec.fluid = "standin_rogue_fluid";
  spec.fluid_args = {"--misbehave", "version"};
  CoupledRun run(spec);
  expect_exit(*run.coupler, kExitProtocolError, 20s,
              "participant 'fluid' speaks coupling protocol version 99, the coupler speaks version 1", "coupler");
  expect_exit(*run.solid, kExitAborted, 6s, "version 99", "solid");
}

TEST(CouplerFaults, NanArrivingAtTheCouplerIsLocatedByParticipantFieldAndIndex) {
  auto spec = long_run("nan-raw");
  spec.fluid = "standin_rogue_fluid";
  spec.fluid_args = {"--misbehave", "nan"};
  CoupledRun run(spec);
  expect_exit(*run.coupler, kExitAborted, 20s,
              "participant 'fluid': non-finite value in interface_point_cloud.positions at index 10 (point 3, component y)",
              "coupler");
  expect_exit(*run.solid, kExitAborted, 6s, "index 10", "solid");
}

TEST(CouplerFaults, NanLeavingAParticipantIsRefusedBeforeItIsSent) {
  auto spec = long_run("nan-library");
  spec.fluid_args = {"--nan-at-window", "3"};
  CoupledRun run(spec);
  expect_exit(*run.fluid, kExitAborted, 20s,
              "participant 'fluid': non-finite value in window_done.loads.forces at index 7 (point 2, component y)",
              "fluid");
  expect_exit(*run.coupler, kExitAborted, 6s, "participant 'fluid' aborted the run", "coupler");
  expect_exit(*run.solid, kExitAborted, 6s, "window_done.loads.forces at index 7", "solid");
}

TEST(CouplerFaults, MessageOutOfOrderIsAProtocolError) {
  auto spec = long_run("order");
  spec.fluid = "standin_rogue_fluid";
  spec.fluid_args = {"--misbehave", "order"};
  CoupledRun run(spec);
  expect_exit(*run.coupler, kExitProtocolError, 20s,
              "participant 'fluid' sent 'window_done' where the coupler expected 'interface_point_cloud'", "coupler");
}

TEST(CouplerFaults, ParticipantThatNeverConnectsIsReportedAfterTheStartupTimeout) {
  auto spec = long_run("absent");
  spec.start_fluid = false;
  spec.startup_timeout_s = 1.0;
  CoupledRun run(spec);
  expect_exit(*run.coupler, kExitPeerLost, 10s, "participant 'fluid' did not connect", "coupler");
  expect_exit(*run.solid, kExitAborted, 6s, "did not connect", "solid");
}

TEST(CouplerFaults, LongStepIsNotAHang) {
  // Each fluid step takes 2.5 peer timeouts of wall time; heartbeats keep everyone patient.
  RunSpec spec = long_run("long-step");
  spec.end_time = 2e-3;
  spec.peer_timeout_s = 0.8;
  spec.fluid_args = {"--step-seconds", "2.0"};
  spec.solid_args = {};
  CoupledRun run(spec);
  const auto codes = run.wait_all(30s);
  ASSERT_EQ(codes.size(), 3u);
  for (const auto& [role, code] : codes) EXPECT_EQ(code, 0) << role << "\n" << run.coupler->log_text();
}

}  // namespace
}  // namespace valvefsi::testing
