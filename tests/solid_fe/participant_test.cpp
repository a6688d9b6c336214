// solid_fe as the coupler's structure participant, as real processes: under the stand-in fluid's
// uniform pressure its cantilever plate moves as in an FE-only run of the same pressure; the
// implicit scheme (checkpoints) gives the explicit result; a killed fluid stops it with a message.
#include <csignal>
#include <cstdio>
#include <regex>
#include <thread>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "coupled_run.hpp"
#include "hexahedron/hex_test_meshes.hpp"
#include "solid_coupled_run.hpp"
#include "test_meshes.hpp"
#include "valvefsi/case/pressure_waveform.hpp"
#include "valvefsi/solid/saint_venant_kirchhoff.hpp"
#include "valvefsi/solid/shell_solver.hpp"

namespace valvefsi::solid::testing {
namespace {

using namespace std::chrono_literals;

constexpr double kPressure_mmHg = 0.001;  // 0.133 Pa: static tip deflection ~0.13 mm on 10 mm

SolidRunSpec cantilever(const std::string& name) {
  SolidRunSpec spec;
  spec.name = name;
  spec.mesh = rectangular_plate(0.01, 0.005, 6, 4, 0.25e-3);
  spec.mesh.node_sets["attachment"] = spec.mesh.node_sets.at("left");
  spec.mesh.node_sets["free_edge_midpoints"] = {grid_node(6, 2, 6)};
  spec.solid_extra = "material: SAINT_VENANT_KIRCHHOFF";
  spec.end_time = 0.01;
  spec.fluid_exe = valvefsi::testing::standin_exe("standin_fluid_pressure");
  spec.fluid_args = {"--pressure", fmt::format("{:.15g}", kPressure_mmHg * kPascalPerMmHg)};
  return spec;
}

double fe_only_tip_deflection() {
  SolidRunSpec spec = cantilever("solid-fe-only-twin");
  spec.waveform = fmt::format("waveform {{ period_s: 0.8 time_s: [0, 0.4] ventricular_pressure_mmHg: [{0}, {0}] "
                              "aortic_pressure_mmHg: [0, 0] }}", kPressure_mmHg);
  SolidCoupledRun run(spec, true);
  EXPECT_EQ(run.wait(60), 0) << run.logs();
  return run.final_monitor("free_edge_midpoints")(2, 0);
}

int repeated_windows(const std::string& log) {
  static const std::regex pattern(R"((\d+) repeated windows)");
  std::smatch m;
  return std::regex_search(log, m, pattern) ? std::stoi(m[1].str()) : -1;
}

TEST(SolidParticipant, ExplicitCouplingMatchesFeOnlyUnderTheSamePressure) {
  const double fe_only = fe_only_tip_deflection();
  SolidCoupledRun run(cantilever("solid-explicit"));
  ASSERT_EQ(run.wait(60), 0) << run.logs();
  const double coupled = run.final_monitor("free_edge_midpoints")(2, 0);
  // The stand-in pushes along +z at triangle centroids (mapped 1/3 to each node, as the FE-only
  // load); FE-only pressure follows the normal, a difference of order slope^2 here (~1e-5).
  EXPECT_GT(fe_only, 1e-5);
  EXPECT_NEAR(coupled, fe_only, 5e-3 * fe_only) << "coupled " << coupled << " m, FE-only " << fe_only << " m";
  std::printf("cantilever tip at 10 ms: FE-only %.6g m, coupled %.6g m (%+.3f %%)\n", fe_only, coupled,
              100 * (coupled / fe_only - 1));
}

TEST(SolidParticipant, ImplicitCouplingRestoresCheckpointsAndGivesTheSameMotion) {
  SolidCoupledRun explicit_run(cantilever("solid-explicit-2"));
  ASSERT_EQ(explicit_run.wait(60), 0) << explicit_run.logs();
  auto spec = cantilever("solid-implicit");
  spec.coupling_extra = "scheme: SERIAL_IMPLICIT acceleration: AITKEN";
  SolidCoupledRun implicit_run(spec);
  ASSERT_EQ(implicit_run.wait(60), 0) << implicit_run.logs();
  EXPECT_GT(repeated_windows(implicit_run.solid->log_text()), 0) << implicit_run.solid->log_text();
  const double a = explicit_run.final_monitor("free_edge_midpoints")(2, 0);
  const double b = implicit_run.final_monitor("free_edge_midpoints")(2, 0);
  EXPECT_NEAR(b, a, 1e-9 * std::abs(a) + 1e-15) << "explicit " << a << ", implicit " << b;
}

TEST(SolidParticipant, KilledFluidStopsTheSolidWithAMessage) {
  auto spec = cantilever("solid-kill-fluid");
  spec.end_time = 100.0;  // never reached
  spec.fluid_args.insert(spec.fluid_args.end(), {"--step-seconds", "0.02"});
  SolidCoupledRun run(spec);
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (std::chrono::steady_clock::now() < deadline && run.solid->log_text().find("coupled (") == std::string::npos) {
    std::this_thread::sleep_for(20ms);
  }
  std::this_thread::sleep_for(300ms);
  ASSERT_TRUE(run.solid->running()) << run.logs();
  run.fluid->send_signal(SIGKILL);
  const auto code = run.solid->wait_for_exit(10s);
  ASSERT_TRUE(code.has_value()) << "solid still running:\n" << run.logs();
  EXPECT_NE(*code, 0);
  EXPECT_NE(run.solid->log_text().find("participant 'fluid'"), std::string::npos) << run.logs();
}

// A peer's crash: the solid's series keeps the samples taken since its last snapshot (before, the
// samples were written only with snapshots, so a run stopped by its peer lost up to a snapshot
// interval of its series). Snapshots here only at t = 0; samples every 1 ms = every window.
TEST(SolidParticipant, KilledFluidLeavesTheSolidSeriesUpToItsLastWindow) {
  auto spec = cantilever("solid-kill-fluid-series");
  spec.end_time = 100.0;  // never reached
  spec.run_extra = "snapshot_interval: 10";
  spec.fluid_args.insert(spec.fluid_args.end(), {"--step-seconds", "0.02"});
  SolidCoupledRun run(spec);
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (std::chrono::steady_clock::now() < deadline && run.solid->log_text().find("coupled (") == std::string::npos) {
    std::this_thread::sleep_for(20ms);
  }
  std::this_thread::sleep_for(600ms);  // ~30 windows of 20 ms pretend work each
  ASSERT_TRUE(run.solid->running()) << run.logs();
  run.fluid->send_signal(SIGKILL);
  const auto code = run.solid->wait_for_exit(10s);
  ASSERT_TRUE(code.has_value()) << "solid still running:\n" << run.logs();
  EXPECT_NE(*code, 0);
  const auto time = valvefsi::testing::read_series(run.output / "solid_series.h5", "/time");
  ASSERT_FALSE(time.empty()) << run.logs();
  // At least 10 windows of the ~30 run before the kill are in the file (the old code: t = 0 only).
  EXPECT_GE(time.back(), 10e-3) << time.size() << " samples, the last at t = " << time.back() << " s\n" << run.logs();
  EXPECT_EQ(run.final_monitor("free_edge_midpoints").cols(), 1);
}

// The energy-growth stop in coupled mode: the cantilever with a forced step just above its
// critical step 2/omega_max (SVK 1 MPa as the case's default, Lanczos) gains energy; solid_fe
// stops with exit code 6 (the solid's own failure), names the energy growth and the element,
// and the coupler is told (docs/solid_fe.md, "Energy-growth stop").
TEST(SolidParticipant, EnergyGrowthStopsTheCoupledSolid) {
  auto spec = cantilever("solid-energy-growth");
  SolverOptions options;
  options.time_step_calibration_interval = 1000000;
  options.max_step_calibration = 10.0;
  ShellModelOptions model_options;
  model_options.fixed_nodes = spec.mesh.node_sets.at("attachment");
  ShellSolver probe(build_shell_model(spec.mesh, model_options), SaintVenantKirchhoff(1e6, 0.3), options);
  probe.advance_window(0.0);
  const double critical = probe.state().calibrated_step;
  ASSERT_GT(critical, 0.0);
  spec.solid_extra += fmt::format(" forced_time_step: {:.15g}", 1.002 * critical);
  spec.end_time = 3000 * critical;
  SolidCoupledRun run(spec);
  EXPECT_EQ(run.wait(60), 6) << run.logs();
  const std::string log = run.solid->log_text();
  for (const char* part : {"energy growth at t =", "Kinetic energy's element: element", "hold this state"}) {
    EXPECT_NE(log.find(part), std::string::npos) << part << " missing in:\n" << run.logs();
  }
  EXPECT_TRUE(std::filesystem::exists(run.output / "solid_series.h5"));
}

// 2D: a plane-strain strip cantilever (20 segments) under the strip fluid's pressure (forces per
// unit depth on the front line) moves as the FE-only strip under the same pressure.
SolidRunSpec strip_cantilever(const std::string& name) {
  SolidRunSpec spec;
  spec.name = name;
  spec.mesh = strip_mesh({straight_polyline({0, 0}, {1, 0}, 0.01, 20)}, 1e-3, 0.5e-3);
  spec.run_extra = "dimension: 2";
  spec.solid_extra = "material: SAINT_VENANT_KIRCHHOFF strip_depth: 1e-3";
  spec.end_time = 0.01;
  spec.fluid_exe = STRIP_PRESSURE_FLUID_EXECUTABLE;
  spec.fluid_args = {"--pressure", fmt::format("{:.15g}", kPressure_mmHg * kPascalPerMmHg)};
  return spec;
}

TEST(SolidParticipant, StripCoupledIn2DMatchesFeOnly) {
  SolidRunSpec twin = strip_cantilever("solid-strip-fe-only");
  twin.waveform = fmt::format("waveform {{ period_s: 0.8 time_s: [0, 0.4] ventricular_pressure_mmHg: [{0}, {0}] "
                              "aortic_pressure_mmHg: [0, 0] }}", kPressure_mmHg);
  SolidCoupledRun fe_only(twin, true);
  ASSERT_EQ(fe_only.wait(60), 0) << fe_only.logs();
  SolidCoupledRun coupled(strip_cantilever("solid-strip-coupled"));
  ASSERT_EQ(coupled.wait(60), 0) << coupled.logs();
  const Eigen::Vector3d a = fe_only.final_monitor("free_edge_midpoints").col(0);
  const Eigen::Vector3d b = coupled.final_monitor("free_edge_midpoints").col(0);
  const double deflection = a.y();
  EXPECT_GT(deflection, 1e-6);
  EXPECT_NEAR(b.y(), deflection, 5e-3 * deflection) << "coupled " << b.y() << " m, FE-only " << deflection << " m";
  EXPECT_EQ(b.z(), 0.0);
  std::printf("2D strip tip at 10 ms: FE-only %.6g m, coupled %.6g m (%+.3f %%)\n", deflection, b.y(),
              100 * (b.y() / deflection - 1));
}

// Energy in coupled runs (docs/solid_fe.md, "Energy in coupled runs"): the solid's figure of the
// coupler's load work equals the coupler's own (sum of power_solid x window size, J/m in 2D, times
// the strip depth); the work the loads do on the solid differs from it by the explicit coupling's
// interface energy error, first order in the window size; the solid's own balance closes.
struct CoupledEnergy {
  double solid_external = 0, solid_interface = 0, coupler_interface = 0, balance_error = 0;
};

CoupledEnergy strip_energy(const std::string& name, double window) {
  SolidRunSpec spec = strip_cantilever(name);
  spec.solid_extra = "material: NEO_HOOKEAN neo_hookean { shear_modulus_kPa: 100 } strip_depth: 1e-3";
  spec.fluid_args = {"--pressure", "100", "--damping", "20"};
  spec.coupling_extra = fmt::format("window_size: {}", window);
  SolidCoupledRun run(spec);
  EXPECT_EQ(run.wait(120), 0) << run.logs();
  CoupledEnergy e;
  const auto series = run.dir / "solid_series.h5";
  e.solid_external = valvefsi::testing::read_series(series, "energy/external_work").back();
  e.solid_interface = valvefsi::testing::read_series(series, "energy/interface_work").back();
  e.balance_error = valvefsi::testing::read_series(series, "energy/relative_balance_error").back();
  const auto power = valvefsi::testing::read_series(run.dir / "coupling_series.h5", "power_solid");
  const auto size = valvefsi::testing::read_series(run.dir / "coupling_series.h5", "window_size");
  for (std::size_t k = 0; k < power.size(); ++k) e.coupler_interface += power[k] * size[k] * 1e-3;  // J/m x depth
  std::printf("window %g s: load work on the solid %.9e J, coupler's book %.9e J (solid's figure %.9e J), "
              "difference %.3e J; balance error %.2e\n", window, e.solid_external, e.coupler_interface,
              e.solid_interface, e.solid_external - e.coupler_interface, e.balance_error);
  return e;
}

TEST(SolidParticipant, CoupledLoadWorkMatchesTheCouplersBookToFirstOrderInTheWindow) {
  const CoupledEnergy coarse = strip_energy("solid-energy-coarse", 2e-4);
  const CoupledEnergy fine = strip_energy("solid-energy-fine", 1e-4);
  for (const auto& e : {coarse, fine}) {
    EXPECT_NEAR(e.solid_interface, e.coupler_interface, 1e-9 * std::abs(e.coupler_interface));
    EXPECT_GT(e.solid_external, 0.0);
    EXPECT_NEAR(e.solid_external, e.coupler_interface, 0.05 * e.solid_external);
    EXPECT_LT(e.balance_error, 1e-3);
  }
  const double ratio = (coarse.solid_external - coarse.coupler_interface) / (fine.solid_external - fine.coupler_interface);
  EXPECT_GT(ratio, 1.6) << "first order in the window size";
  EXPECT_LT(ratio, 2.5);
  std::printf("difference ratio for halved windows: %.3f\n", ratio);
}

// Bricks as the participant: the fluid sees the mid-surface (pairs of ventricular/aortic nodes),
// its forces go half to each node of a pair. Under the stand-in pressure the brick cantilever
// moves as the FE-only bricks under the same pressure on their ventricular faces.
SolidRunSpec brick_cantilever(const std::string& name) {
  SolidRunSpec spec = cantilever(name);
  spec.mesh = box_mesh(0.01, 0.005, 0.25e-3, 6, 4, 1);
  spec.mesh.node_sets["attachment"] = spec.mesh.node_sets.at("x0");
  spec.mesh.node_sets["free_edge_midpoints"] = {box_node(6, 2, 0, 6, 4), box_node(6, 2, 1, 6, 4)};
  spec.solid_extra = "element_family: HEXAHEDRON material: SAINT_VENANT_KIRCHHOFF";
  return spec;
}

TEST(SolidParticipant, BricksCoupledThroughTheirMidSurfaceMatchFeOnly) {
  SolidRunSpec twin = brick_cantilever("solid-brick-fe-only-twin");
  twin.waveform = fmt::format("waveform {{ period_s: 0.8 time_s: [0, 0.4] ventricular_pressure_mmHg: [{0}, {0}] "
                              "aortic_pressure_mmHg: [0, 0] }}", kPressure_mmHg);
  SolidCoupledRun fe_only_run(twin, true);
  ASSERT_EQ(fe_only_run.wait(60), 0) << fe_only_run.logs();
  SolidCoupledRun run(brick_cantilever("solid-brick-explicit"));
  ASSERT_EQ(run.wait(60), 0) << run.logs();
  const double fe_only = fe_only_run.final_monitor("free_edge_midpoints").row(2).mean();
  const double coupled = run.final_monitor("free_edge_midpoints").row(2).mean();
  std::printf("brick cantilever tip (mid-surface) at 10 ms: coupled %.6g m, FE-only %.6g m\n", coupled, fe_only);
  // The same total load; the stand-in spreads it by the mid-surface triangles (1/3 per node, along
  // +z), the FE-only faces by the bilinear shape functions along the normal (measured: equal to
  // 6 digits).
  EXPECT_GT(fe_only, 1e-5);
  EXPECT_NEAR(coupled, fe_only, 5e-3 * std::abs(fe_only));
}

// The implicit solid as the participant (solid.time_integration: IMPLICIT, 3D shells): its
// generalized-alpha steps (at most solid.max_time_step, 0.1 ms) land on the coupler's 1 ms windows.
// Under the stand-in's constant pressure the tip follows the explicit coupled run's to the scheme's
// time-discretisation error (measured -0.005 % at 10 ms; bound 0.1 %); with the implicit coupling
// scheme the restored checkpoints give the same motion to round-off (the load does not depend on it).
TEST(SolidParticipant, ImplicitSolidLandsOnTheWindowsAndFollowsTheExplicitSolid) {
  SolidCoupledRun explicit_run(cantilever("solid-explicit-3"));
  ASSERT_EQ(explicit_run.wait(60), 0) << explicit_run.logs();
  auto spec = cantilever("solid-implicit-solid");
  spec.solid_extra += " time_integration: IMPLICIT spectral_radius_infinity: 0.5";
  SolidCoupledRun implicit_solid(spec);
  ASSERT_EQ(implicit_solid.wait(60), 0) << implicit_solid.logs();
  EXPECT_NE(implicit_solid.solid->log_text().find("implicit generalized-alpha steps"), std::string::npos)
      << implicit_solid.logs();
  spec.name = "solid-implicit-solid-implicit-coupling";
  spec.coupling_extra = "scheme: SERIAL_IMPLICIT acceleration: AITKEN";
  SolidCoupledRun both(spec);
  ASSERT_EQ(both.wait(60), 0) << both.logs();
  EXPECT_GT(repeated_windows(both.solid->log_text()), 0) << both.solid->log_text();
  const double a = explicit_run.final_monitor("free_edge_midpoints")(2, 0);
  const double b = implicit_solid.final_monitor("free_edge_midpoints")(2, 0);
  const double c = both.final_monitor("free_edge_midpoints")(2, 0);
  std::printf("cantilever tip at 10 ms: explicit solid %.9g m, implicit solid %.9g m (%+.3f %%), with implicit "
              "coupling %.9g m\n", a, b, 100 * (b / a - 1), c);
  EXPECT_GT(a, 1e-5);
  EXPECT_NEAR(b, a, 1e-3 * std::abs(a));
  EXPECT_NEAR(c, b, 1e-9 * std::abs(b) + 1e-15);
}

// AUTOMATIC switches on the case's pressure waveform, which a coupled run does not apply.
TEST(SolidParticipant, AutomaticSwitchIsRejectedInACoupledRun) {
  auto spec = cantilever("solid-automatic-coupled");
  spec.solid_extra += " time_integration: AUTOMATIC";
  SolidCoupledRun run(spec);
  EXPECT_EQ(run.wait(60), 2) << run.logs();
  EXPECT_NE(run.solid->log_text().find("field 'solid.time_integration' = AUTOMATIC in a coupled run"),
            std::string::npos)
      << run.logs();
}

}  // namespace
}  // namespace valvefsi::solid::testing
