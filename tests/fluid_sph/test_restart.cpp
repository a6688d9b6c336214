// fluid_sph restart files through the real coupler (docs/coupling.md, "Restarts"): a 2D water
// column collapsing in a tank, coupled with the stand-in leaflet solid. One run goes straight
// to 2T writing restart points; a second run continues from the point at T. Bit for bit: the
// final particles (order, positions, velocities), every probe row after T, and the coupler's
// force series. Once with the fluid ignoring the solid's surface (interface_model NONE), once
// with the 2D thin wall in the column (skipped while its model cannot write restart state).
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <map>

#include <unistd.h>

#include "coupled_run.hpp"
#include "process_harness.hpp"

namespace {

using valvefsi::testing::ChildProcess;
using valvefsi::testing::read_series;

constexpr double kEnd = 0.02;  // 2T
constexpr int kSnapshotsPerRun = 4;

struct RunResult {
  std::filesystem::path dir;
  int fluid = -1, solid = -1, coupler = -1;
  std::string fluid_log, coupler_log;
};

// ranks > 1: the fluid runs under mpiexec, split into slabs (rank 0 talks to the coupler).
RunResult run(const std::string& name, const std::string& interface_model, const std::string& restart_from, int ranks = 1) {
  RunResult r;
  r.dir = valvefsi::testing::fresh_directory(name);
  const auto case_file = r.dir / "case.textproto";
  // Shifting on (its kernel sums are restart state too), fixed-wall loads booked every step.
  valvefsi::testing::write_file(
      case_file, fmt::format(R"(run {{ end_time: {} output_dir: "{}" dimension: 2 series_interval: 0.001 snapshot_interval: {} }}
fluid {{
  particle_spacing: 0.005
  density: 1000
  dynamic_viscosity: 0.001
  sound_speed: 20
  artificial_viscosity: 0.02
  shifting: 1
  gravity: [0, -9.81]
  domain_lower: [-0.03, -0.03]
  domain_upper: [0.18, 0.3]
  fluid_blocks {{ box {{ lower: [0, 0] upper: [0.05, 0.1] }} }}
  walls {{ container {{ lower: [0, 0] upper: [0.15, 10] }} }}
  probes {{ pressure_points {{ name: "bottom" position: [0.02, 0.01] }} wall_forces: true }}
  thin_walls {{ }}
  interface_model: {}
}}
coupling {{
  scheme: SERIAL_EXPLICIT
  window_size: 1e-4
  mapping: NEAREST_PROJECTION
  endpoint: "ipc://{}/c.ipc"
  heartbeat_interval_s: 0.1
  peer_timeout_s: 3
  startup_timeout_s: 60
  {}
}}
)",
                             kEnd, r.dir.string(), kEnd / kSnapshotsPerRun, interface_model, r.dir.string(),
                             restart_from.empty() ? "restart_interval_s: 0.005 restart_keep: 4" : ""));
  const std::vector<std::string> common = {"--case", case_file.string(), "--output", r.dir.string()};
  auto with = [&](std::vector<std::string> argv, const std::vector<std::string>& extra) {
    argv.insert(argv.end(), extra.begin(), extra.end());
    argv.insert(argv.end(), common.begin(), common.end());
    return argv;
  };
  std::vector<std::string> coupler_extra;
  if (!restart_from.empty()) coupler_extra = {"--restart", restart_from};
  ChildProcess coupler(with({valvefsi::testing::coupler_exe()}, coupler_extra), r.dir / "coupler.log");
  // A still leaflet standing in the column at x = 0.025, from inside the floor to above the water.
  ChildProcess solid(with({VALVEFSI_TEST_LEAFLET_SOLID}, {"--x", "0.025", "--y0", "-0.01", "--y1", "0.14", "--nodes", "31"}),
                     r.dir / "solid.log");
  std::vector<std::string> fluid_command = {VALVEFSI_TEST_FLUID_SPH};
  if (ranks > 1) {
    fluid_command = {VALVEFSI_TEST_MPIEXEC, "-n", std::to_string(ranks), "--oversubscribe"};
    if (::geteuid() == 0) fluid_command.push_back("--allow-run-as-root");
    fluid_command.push_back(VALVEFSI_TEST_FLUID_SPH);
  }
  ChildProcess fluid(with(fluid_command, {"--threads", "1"}), r.dir / "fluid.log",
                     std::vector<std::string>{"VALVEFSI_COUPLER_ENDPOINT=ipc://" + r.dir.string() + "/c.ipc"});
  const auto f = fluid.wait_for_exit(std::chrono::seconds(240));
  const auto s = solid.wait_for_exit(std::chrono::seconds(20));
  const auto c = coupler.wait_for_exit(std::chrono::seconds(20));
  r.fluid = f.value_or(-1000);
  r.solid = s.value_or(-1000);
  r.coupler = c.value_or(-1000);
  r.fluid_log = fluid.log_text();
  r.coupler_log = coupler.log_text();
  return r;
}

template <class T>
std::vector<T> tail(const std::vector<T>& all, std::size_t n) {
  return {all.end() - static_cast<std::ptrdiff_t>(std::min(n, all.size())), all.end()};
}

void expect_restart_continues_bit_for_bit(const std::string& name, const std::string& interface_model, int ranks = 1) {
  const RunResult whole = run(name + "-whole", interface_model, "", ranks);
  if (whole.fluid_log.find("no restart capability") != std::string::npos)
    GTEST_SKIP() << "the immersed-surface model cannot write restart state yet:\n" << whole.fluid_log;
  ASSERT_EQ(whole.fluid, 0) << whole.fluid_log;
  ASSERT_EQ(whole.coupler, 0) << whole.coupler_log;
  const auto point = whole.dir / "restart" / "t_0.010000000";
  ASSERT_TRUE(std::filesystem::exists(point / "COMPLETE")) << whole.coupler_log;
  ASSERT_TRUE(std::filesystem::exists(point / "fluid.restart.h5"));
  for (int k = 1; k < ranks; ++k) ASSERT_TRUE(std::filesystem::exists(point / fmt::format("fluid.rank{}.restart.h5", k)));

  const RunResult resumed = run(name + "-resumed", interface_model, point.string(), ranks);
  ASSERT_EQ(resumed.fluid, 0) << resumed.fluid_log;
  ASSERT_EQ(resumed.coupler, 0) << resumed.coupler_log;
  EXPECT_NE(resumed.fluid_log.find("continuing from"), std::string::npos) << resumed.fluid_log;

  // The last snapshot (t = 2T): same particles in the same order, same doubles.
  const auto last_whole = fmt::format("snapshot_{:06d}/", kSnapshotsPerRun);
  const auto last_resumed = fmt::format("snapshot_{:06d}/", kSnapshotsPerRun / 2);
  for (const char* field : {"id", "position", "velocity", "pressure", "density"}) {
    const auto a = read_series(whole.dir / "fluid_particles.h5", last_whole + field);
    const auto b = read_series(resumed.dir / "fluid_particles.h5", last_resumed + field);
    ASSERT_FALSE(a.empty()) << field;
    EXPECT_EQ(a, b) << field;
  }
  // The probe rows after T and the coupler's interface force series, bit for bit.
  const auto rows = read_series(resumed.dir / "fluid_probes.h5", "time").size();
  ASSERT_GE(rows, 10u);
  for (const char* dataset : {"time", "pressure/bottom", "wall_force/fixed_walls", "lost_particles", "interface/force"}) {
    const auto a = read_series(whole.dir / "fluid_probes.h5", dataset);
    const auto b = read_series(resumed.dir / "fluid_probes.h5", dataset);
    const std::size_t width = b.size() / rows;
    EXPECT_EQ(tail(a, width * rows), b) << dataset;
  }
  const auto windows = read_series(resumed.dir / "coupling_series.h5", "time").size();
  ASSERT_GE(windows, 90u);
  for (const char* dataset : {"time", "force_fluid"}) {
    const std::size_t width = std::string(dataset) == "force_fluid" ? 3 : 1;
    EXPECT_EQ(tail(read_series(whole.dir / "coupling_series.h5", dataset), width * windows),
              read_series(resumed.dir / "coupling_series.h5", dataset))
        << dataset;
  }
  // The collapsing column has moved: the comparison is of a flow, not of a fluid at rest.
  const auto first = read_series(whole.dir / "fluid_particles.h5", "snapshot_000000/position");
  const auto first_id = read_series(whole.dir / "fluid_particles.h5", "snapshot_000000/id");
  const auto last = read_series(whole.dir / "fluid_particles.h5", last_whole + "position");
  const auto last_id = read_series(whole.dir / "fluid_particles.h5", last_whole + "id");
  ASSERT_EQ(first.size(), last.size());
  std::map<double, std::size_t> where;
  for (std::size_t i = 0; i < first_id.size(); ++i) where[first_id[i]] = i;
  double moved = 0;
  for (std::size_t i = 0; i < last_id.size(); ++i)
    for (int d = 0; d < 3; ++d) moved = std::max(moved, std::abs(first[3 * where[last_id[i]] + d] - last[3 * i + d]));
  std::printf("%s: %zu probe rows and %zu windows after the restart equal bit for bit; largest travel %.4f m\n", name.c_str(),
              rows, windows, moved);
  EXPECT_GT(moved, 0.002);
}

TEST(FluidRestart, FluidWithoutLeafletContinuesBitForBit) {
  expect_restart_continues_bit_for_bit("fluid_restart_plain", "NONE");
}

TEST(FluidRestart, FluidWithThinWallLeafletContinuesBitForBit) {
  expect_restart_continues_bit_for_bit("fluid_restart_thin_wall", "THIN_WALL");
}

// The fluid split over two MPI ranks under the coupler: restart files per rank continue bit
// for bit, and the split run's probes equal the one-rank run's (to round-off).
TEST(FluidRestart, FluidOnTwoRanksContinuesBitForBitAndMatchesOneRank) {
  expect_restart_continues_bit_for_bit("fluid_restart_split", "NONE", 2);
  const RunResult single = run("fluid_restart_single", "NONE", "", 1);
  ASSERT_EQ(single.fluid, 0) << single.fluid_log;
  const auto split_dir = std::filesystem::temp_directory_path() / ("vfsi-fluid_restart_split-whole-" + std::to_string(::getpid()));
  for (const char* dataset : {"pressure/bottom", "wall_force/fixed_walls"}) {
    const auto split = read_series(split_dir / "fluid_probes.h5", dataset);
    const auto one = read_series(single.dir / "fluid_probes.h5", dataset);
    ASSERT_EQ(split.size(), one.size());
    double worst = 0, scale = 0;
    for (std::size_t i = 0; i < split.size(); ++i) {
      worst = std::max(worst, std::abs(split[i] - one[i]));
      scale = std::max(scale, std::abs(one[i]));
    }
    std::printf("%s, 2 ranks vs 1: largest difference %.3e of %.3e\n", dataset, worst, scale);
    EXPECT_LE(worst, 1e-6 * scale) << dataset;
  }
}

}  // namespace
