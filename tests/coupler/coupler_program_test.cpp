// Pieces of the coupler program that need no second process: the window sizing rule, the
// settings taken from a case, and the HDF5 series surviving a crash of its writer.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include "coupled_run.hpp"
#include "process_harness.hpp"
#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/coupler/coupler_settings.hpp"
#include "valvefsi/coupler/coupling_schemes.hpp"
#include "valvefsi/coupler/series_writer.hpp"

namespace valvefsi::coupler {
namespace {

TEST(WindowSize, SmallestOfCaseAndPositiveProposals) {
  EXPECT_DOUBLE_EQ(next_window_size(0.0, 1.0, 1e-3, 0.0, 0.0), 1e-3);
  EXPECT_DOUBLE_EQ(next_window_size(0.0, 1.0, 1e-3, 4e-4, 0.0), 4e-4);
  EXPECT_DOUBLE_EQ(next_window_size(0.0, 1.0, 1e-3, 4e-4, 3e-4), 3e-4);
  EXPECT_DOUBLE_EQ(next_window_size(0.0, 1.0, 1e-3, 2e-3, 0.0), 1e-3);
}

TEST(WindowSize, LastWindowLandsExactlyOnTheEndTime) {
  EXPECT_DOUBLE_EQ(next_window_size(0.9995, 1.0, 1e-3, 0.0, 0.0), 1.0 - 0.9995);
  // A sliver left by rounding is absorbed, not run as a window of its own.
  const double start = 1.0 - 1e-3 - 1e-12;
  EXPECT_EQ(next_window_size(start, 1.0, 1e-3, 0.0, 0.0), 1.0 - start);
}

TEST(CouplerSettings, DefaultsFromAnEmptyCouplingSection) {
  const auto run_case = parse_case_text("run { end_time: 0.5 } coupling { }", "inline.textproto");
  const auto settings = settings_from_case(run_case, "/tmp/vfsi-settings");
  EXPECT_EQ(settings.scheme, SchemeKind::serial_explicit);
  EXPECT_EQ(scheme_label(settings), "serial-explicit");
  EXPECT_DOUBLE_EQ(settings.window_size, 1e-3);
  EXPECT_DOUBLE_EQ(settings.end_time, 0.5);
  EXPECT_EQ(settings.endpoint, "ipc:///tmp/vfsi-settings/coupler.ipc");
  EXPECT_EQ(settings.series_file, std::filesystem::path("/tmp/vfsi-settings/coupling_series.h5"));
  EXPECT_DOUBLE_EQ(settings.max_interface_speed, 20.0);
  EXPECT_DOUBLE_EQ(settings.runaway_oscillation_speed, 0.5);
  EXPECT_EQ(settings.runaway_growing_blocks, 12);
  EXPECT_EQ(settings.runaway_standing_speed, 0.0);
  EXPECT_EQ(settings.runaway_standing_blocks, 8);
  EXPECT_EQ(settings.mapping.method, coupling::MappingMethod::nearest_projection);
}

TEST(CouplerSettings, ImplicitSchemeNamesItsAcceleration) {
  const auto run_case = parse_case_text(
      "run { end_time: 1 } coupling { scheme: SERIAL_IMPLICIT acceleration: IQN_ILS max_iterations: 7 }", "inline");
  const auto settings = settings_from_case(run_case, "/tmp");
  EXPECT_EQ(scheme_label(settings), "serial-implicit/iqn-ils");
  EXPECT_EQ(settings.max_iterations, 7);
}

TEST(CouplerSettings, OutOfRangeValueIsRejectedWithFieldAndLimit) {
  try {
    (void)parse_case_text("run { end_time: 1 }\ncoupling { peer_timeout_s: -1 }", "bad.textproto");
    FAIL() << "accepted a negative peer timeout";
  } catch (const CaseError& error) {
    EXPECT_NE(std::string(error.what()).find("coupling.peer_timeout_s"), std::string::npos) << error.what();
  }
}

TEST(SeriesWriter, RowsFlushedBeforeACrashStayReadable) {
  const auto dir = valvefsi::testing::fresh_directory("series");
  const auto file = dir / "series.h5";
  const pid_t child = ::fork();
  if (child == 0) {
    SeriesWriter writer(file, {{"time", 1, "s", ""}, {"force", 3, "N", ""}}, 3);
    for (int row = 0; row < 7; ++row) {
      const double values[] = {0.1 * row, 1.0 * row, 2.0 * row, 3.0 * row};
      writer.append(values);
    }
    ::_exit(0);  // a crash: no destructor, no close; rows 7 (buffered) is lost, 0-5 are on disk
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  const auto time = valvefsi::testing::read_series(file, "time");
  const auto force = valvefsi::testing::read_series(file, "force");
  ASSERT_EQ(time.size(), 6u);
  ASSERT_EQ(force.size(), 18u);
  EXPECT_DOUBLE_EQ(time[5], 0.5);
  EXPECT_DOUBLE_EQ(force[3 * 5 + 2], 15.0);
}

TEST(SeriesWriter, AllRowsAfterANormalCloseAndWrongRowLengthRefused) {
  const auto file = valvefsi::testing::fresh_directory("series-ok") / "series.h5";
  {
    SeriesWriter writer(file, {{"a", 1, "", ""}, {"b", 2, "", ""}}, 4);
    for (int row = 0; row < 5; ++row) {
      const double values[] = {1.0 * row, 0.0, -1.0 * row};
      writer.append(values);
    }
    const double short_row[] = {1.0};
    EXPECT_THROW(writer.append(short_row), std::invalid_argument);
  }
  EXPECT_EQ(valvefsi::testing::read_series(file, "a").size(), 5u);
  EXPECT_DOUBLE_EQ(valvefsi::testing::read_series(file, "b")[9], -4.0);
}

}  // namespace
}  // namespace valvefsi::coupler
