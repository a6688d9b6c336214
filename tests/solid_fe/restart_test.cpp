// solid_fe restarts (docs/solid_fe.md, "Restarts"): a coupled run through the real coupler and a
// restartable 2D test fluid, continued with `coupler --restart` from its first restart point,
// ends with the same displacements bit for bit as the uninterrupted run; so does an FE-only run
// continued with `solid_fe --fe-only --restart`. Both runs tie the flap's tip (its catches and
// releases are state too), and the fluid's drag makes the loads depend on the solid's motion.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "coupled_run.hpp"
#include "solid_coupled_run.hpp"
#include "test_meshes.hpp"
#include "valvefsi/coupling/restart_file.hpp"

namespace valvefsi::solid::testing {
namespace {

// A flap attached at (0, 10 mm) with its tip at (1 mm, 0), the coaptation plane x = -t/2 under it.
SolidRunSpec tied_flap(const std::string& name) {
  SolidRunSpec spec;
  spec.name = name;
  std::vector<Eigen::Vector2d> line;
  for (int i = 0; i <= 20; ++i) line.emplace_back(1e-3 * i / 20.0, 0.01 * (1.0 - i / 20.0));
  spec.mesh = strip_mesh({line}, 1e-3, 0.25e-3);
  spec.mesh.contact_planes["annulus"] = Plane{Eigen::Vector3d(-0.125e-3, 0, 0), Eigen::Vector3d::UnitX()};
  spec.run_extra = "dimension: 2";
  spec.solid_extra = "material: NEO_HOOKEAN neo_hookean { shear_modulus_kPa: 100 } strip_depth: 1e-3 "
                     "coaptation_tie { contact_plane: \"annulus\" release_force_N_per_m: 0.5 }";
  spec.end_time = 0.012;
  spec.fluid_exe = STRIP_PRESSURE_FLUID_EXECUTABLE;
  // Shut by a reverse pressure, pulled open by a forward one from 6 ms on, with drag.
  spec.fluid_args = {"--pressure", "-1000", "--damping", "50", "--flip-time", "0.006"};
  return spec;
}

// The last field snapshot's node positions (every node, 3 per node) of a run's output folder;
// `suffix` names a restarted run's files in the first run's folder.
std::vector<double> final_positions(const std::filesystem::path& dir, const std::string& suffix = "") {
  const auto times = valvefsi::testing::read_series(dir / ("solid_series" + suffix + ".h5"), "snapshots/time");
  if (times.empty()) return {};
  return valvefsi::testing::read_series(dir / ("solid_fields" + suffix + ".h5"),
                                        fmt::format("snapshots/{:06d}/position", times.size() - 1));
}

std::vector<std::string> restart_folders(const std::filesystem::path& run) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(run / "restart")) {
    if (e.is_directory()) names.push_back(e.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

TEST(SolidRestart, CoupledRunContinuesBitForBitThroughTheCoupler) {
  auto whole_spec = tied_flap("solid-restart-whole");
  whole_spec.coupling_extra = "restart_interval_s: 0.004 restart_keep: 3";
  SolidCoupledRun whole(whole_spec);
  ASSERT_EQ(whole.wait(120), 0) << whole.logs();
  const auto folders = restart_folders(whole.output);
  ASSERT_GE(folders.size(), 2u) << whole.logs();
  const auto point = whole.output / "restart" / folders.front();  // ~4 ms: before the flip
  ASSERT_TRUE(std::filesystem::exists(point / "COMPLETE"));
  const coupling::RestartReader saved(coupling::restart_file_path(point, "solid"));
  EXPECT_GE(saved.integer("solid/tie/captures"), 1) << "the tie has acted before the point";

  auto resumed_spec = tied_flap("solid-restart-resumed");
  resumed_spec.coupler_args = {"--restart", point.string()};
  SolidCoupledRun resumed(resumed_spec);
  ASSERT_EQ(resumed.wait(120), 0) << resumed.logs();
  EXPECT_NE(resumed.solid->log_text().find("continuing from"), std::string::npos) << resumed.logs();

  const auto a = final_positions(whole.output);
  const auto b = final_positions(resumed.output);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_TRUE(a == b) << "final positions differ after the restart";
  for (const char* series : {"energy/external_work", "energy/interface_work", "energy/tie_work", "tie/releases"}) {
    const auto x = valvefsi::testing::read_series(whole.output / "solid_series.h5", series);
    const auto y = valvefsi::testing::read_series(resumed.output / "solid_series.h5", series);
    ASSERT_FALSE(x.empty() || y.empty()) << series;
    EXPECT_EQ(x.back(), y.back()) << series;
  }
  const auto releases = valvefsi::testing::read_series(whole.output / "solid_series.h5", "tie/releases");
  EXPECT_GE(releases.back(), 1.0) << "the forward pull released the tie after the restart point";
  std::size_t differing = 0;
  for (std::size_t k = 0; k < a.size(); ++k) differing += a[k] != b[k];
  std::printf("coupled restart from %s: %zu of %zu final coordinates differ; tie releases %g\n",
              folders.front().c_str(), differing, a.size(), releases.back());
}

TEST(SolidRestart, FeOnlyRunContinuesBitForBitInItsOwnFolder) {
  auto spec = tied_flap("solid-restart-fe-only");
  spec.waveform = "waveform { period_s: 0.8 time_s: [0, 0.006, 0.0061, 0.4] ventricular_pressure_mmHg: [0, 0, 3, 3] "
                  "aortic_pressure_mmHg: [7.5, 7.5, 0, 0] }";
  spec.solid_extra += " restart_interval_s: 0.004 restart_keep: 3 mass_damping_per_s: 50";
  SolidCoupledRun whole(spec, true);
  ASSERT_EQ(whole.wait(120), 0) << whole.logs();
  // Points at 4, 8 and 12 ms (the end: a finished run can be continued to a later end time).
  EXPECT_EQ(restart_folders(whole.output),
            (std::vector<std::string>{"t_0.004000000", "t_0.008000000", "t_0.012000000"}));

  // Continue from the first point in the same folder: the new files carry the restart time.
  auto again = spec;
  again.name = "solid-restart-fe-only-again";
  again.output_dir = whole.output.string();
  again.solid_args = {"--restart", (whole.output / "restart" / "t_0.004000000").string()};
  SolidCoupledRun resumed(again, true);
  ASSERT_EQ(resumed.wait(120), 0) << resumed.logs();
  const auto a = final_positions(whole.output);
  const auto b = final_positions(whole.output, "_t_0.004000000");
  ASSERT_EQ(a.size(), b.size());
  EXPECT_TRUE(a == b) << "final positions differ after the FE-only restart";

  // A run's restart/ folder means its LATEST point.
  again.name = "solid-restart-fe-only-latest";
  again.output_dir.clear();
  again.solid_args = {"--restart", (whole.output / "restart").string()};
  SolidCoupledRun latest(again, true);
  ASSERT_EQ(latest.wait(120), 0) << latest.logs();
  EXPECT_NE(latest.solid->log_text().find("t_0.012000000"), std::string::npos) << latest.logs();
  EXPECT_TRUE(final_positions(latest.output) == a);
}

TEST(SolidRestart, RefusesARestartFileOfAnotherMesh) {
  auto spec = tied_flap("solid-restart-other-mesh");
  spec.solid_extra += " restart_interval_s: 0.004";
  spec.end_time = 0.004;
  SolidCoupledRun first(spec, true);
  ASSERT_EQ(first.wait(60), 0) << first.logs();
  auto other = tied_flap("solid-restart-other-mesh-2");
  std::vector<Eigen::Vector2d> line;
  for (int i = 0; i <= 10; ++i) line.emplace_back(1e-3 * i / 10.0, 0.01 * (1.0 - i / 10.0));
  other.mesh = strip_mesh({line}, 1e-3, 0.25e-3);
  other.mesh.contact_planes["annulus"] = spec.mesh.contact_planes.at("annulus");
  other.solid_args = {"--restart", (first.output / "restart").string()};
  SolidCoupledRun refused(other, true);
  EXPECT_NE(refused.wait(60), 0);
  EXPECT_NE(refused.solid->log_text().find("written for a mesh of 42 nodes; this case's mesh has 22"), std::string::npos) << refused.logs();
}

}  // namespace
}  // namespace valvefsi::solid::testing
