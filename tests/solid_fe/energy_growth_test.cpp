// The energy-growth stop (docs/solid_fe.md, "Energy-growth stop"): a small pressurised plate run
// with a forced step just above its critical step 2/omega_max gains energy and is stopped when
// the balance error passes 0.2 of the largest energy seen, before anything overflows, naming the
// node where the kinetic energy sits; just below the critical step the same run closes its
// balance and is not stopped. Through the program: exit code 3, the message, and the output
// files holding the stopped state.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include <gtest/gtest.h>
#include <sys/wait.h>

#include "test_meshes.hpp"
#include "valvefsi/solid/energy_growth_error.hpp"
#include "valvefsi/solid/mhgo.hpp"
#include "valvefsi/solid/saint_venant_kirchhoff.hpp"
#include "valvefsi/solid/material.hpp"
#include "valvefsi/solid/shell_solver.hpp"

namespace valvefsi::solid::testing {
namespace {

Mesh plate_mesh() {
  Mesh mesh = rectangular_plate(0.01, 0.005, 6, 3, 0.25e-3);
  mesh.node_sets["attachment"] = mesh.node_sets.at("left");
  return mesh;
}

ShellModel plate_model() {
  const Mesh mesh = plate_mesh();
  ShellModelOptions options;
  options.fixed_nodes = mesh.node_sets.at("attachment");
  return build_shell_model(mesh, options);
}

constexpr double kYoungsModulus = 1e6, kPoisson = 0.3, kPressure = 5.0;  // Pa (small deflection: the unloaded critical step holds)

// 2/omega_max of the unloaded plate (Lanczos, no cap).
double critical_step() {
  SolverOptions options;
  options.time_step_calibration_interval = 1000000;
  options.max_step_calibration = 10.0;
  ShellSolver solver(plate_model(), SaintVenantKirchhoff(kYoungsModulus, kPoisson), options);
  solver.advance_window(0.0);
  return solver.state().calibrated_step;
}

std::unique_ptr<ShellSolver> forced_run(double dt) {
  SolverOptions options;
  options.fixed_time_step = dt;
  options.max_energy_balance_error = 0.2;
  auto solver = std::make_unique<ShellSolver>(plate_model(), SaintVenantKirchhoff(kYoungsModulus, kPoisson), options);
  solver->set_pressure_waveform([](double) { return kPressure; });
  return solver;
}

TEST(EnergyGrowthStop, UnstableForcedStepIsStoppedBeforeAnythingOverflows) {
  const double critical = critical_step();
  ASSERT_GT(critical, 0.0);
  auto solver = forced_run(1.002 * critical);
  std::string message;
  std::int64_t node = -1;
  try {
    solver->advance_window(3000 * critical);
  } catch (const EnergyGrowthError& e) {
    message = e.what();
    node = e.hottest_node();
  }
  const SolverState& s = solver->state();
  std::printf("forced step 1.002 x 2/omega_max: stopped at step %lld, balance %.3g of the largest energy %.3g J\n",
              static_cast<long long>(s.step), s.energy.balance_error_of_largest(), s.energy.largest_energy);
  ASSERT_FALSE(message.empty()) << "the run was not stopped; balance error " << s.energy.balance_error_of_largest();
  EXPECT_GT(s.energy.balance_error_of_largest(), 0.2);
  EXPECT_LT(s.energy.balance_error_of_largest(), 0.3) << "stopped soon after the limit was passed";
  EXPECT_TRUE(s.velocity.allFinite() && s.position.allFinite()) << "stopped too late";
  EXPECT_TRUE(std::isfinite(s.energy.kinetic));
  // The named node is the one with the most kinetic energy.
  const Eigen::VectorXd& m = solver->elements().nodal_mass();
  Eigen::Index hottest = 0;
  (m.array() * s.velocity.colwise().squaredNorm().transpose().array()).maxCoeff(&hottest);
  EXPECT_EQ(node, hottest);
  for (const char* part : {"energy growth at t =", "solid.max_energy_balance_error = 0.2", "kinetic",
                           "external work", "concentrates at node", "solid.time_step_safety"}) {
    EXPECT_NE(message.find(part), std::string::npos) << part << " missing in: " << message;
  }
  EXPECT_NE(message.find("node " + std::to_string(node)), std::string::npos) << message;
  // The growth is judged on the plate's own energies: a floor above them would hold the stop back
  // until the balance passed 0.2 of the floor, past the bound 0.3 of the largest energy above.
  std::printf("  largest energy %.3g J, the model's floor %.3g J\n", s.energy.largest_energy,
              solver->energy_check_floor());
  EXPECT_GT(s.energy.largest_energy, solver->energy_check_floor());
  // The measure the progress lines print is the one that stopped the run (explicit: no scheme
  // dissipation; above the floor: the balance over the largest energy seen).
  EXPECT_DOUBLE_EQ(solver->energy_growth_measure(), s.energy.balance_error_of_largest());
}

// The floor is the strain energy of the model under a volume-preserving stretch of 1e-3 along x;
// for the flat SVK plate that is the plane-stress energy of the Green strains it gives
// (bending zero), times the plate's volume.
TEST(EnergyGrowthStop, FloorIsTheStrainEnergyOfTheModelAtAStrainOfOneInAThousand) {
  ShellSolver solver(plate_model(), SaintVenantKirchhoff(kYoungsModulus, kPoisson));
  const double e = kEnergyFloorStrain;
  const double exx = 0.5 * ((1.0 + e) * (1.0 + e) - 1.0);
  const double eyy = 0.5 * (1.0 / (1.0 + e) - 1.0);
  const double volume = 0.01 * 0.005 * 0.25e-3;
  const double expected = volume * kYoungsModulus / (2.0 * (1.0 - kPoisson * kPoisson)) *
                          (exx * exx + eyy * eyy + 2.0 * kPoisson * exx * eyy);
  std::printf("floor of the SVK plate: %.6g J (plane stress %.6g J)\n", solver.energy_check_floor(), expected);
  EXPECT_NEAR(solver.energy_check_floor(), expected, 1e-6 * expected);
}

// Session 8's false stop: a coupled 2D leaflet (MHGO, 0.25 mm thick, 1 mm deep, 2200 kg/m3)
// stopped at 1.84 ms with a balance error of 0.218 of the largest energy seen, 8.6e-14 J, while it
// had barely moved. The same ledger on a leaflet of that size (12 mm) is not stopped: the model's
// floor (its strain energy at a strain of 1e-3) is the scale below which energies are not judged.
TEST(EnergyGrowthStop, RoundOffSizedLedgerOfABarelyMovedLeafletIsNotStopped) {
  Mesh mesh = rectangular_plate(0.012, 0.001, 12, 1, 0.25e-3);
  ShellModelOptions model;
  model.fixed_nodes = mesh.node_sets.at("left");
  model.density = 2200.0;
  SolverOptions options;
  options.max_energy_balance_error = 0.2;
  options.fixed_time_step = 1e-7;
  ShellSolver solver(build_shell_model(mesh, model), Material{Mhgo{}}, options);
  SolverState ledger = solver.state();
  ledger.step = 1000;
  ledger.energy.external_work = 8.6e-14;
  ledger.energy.internal_work = (1.0 - 0.218) * 8.6e-14;
  ledger.energy.largest_energy = 8.6e-14;
  solver.restore(ledger);
  EXPECT_NO_THROW(solver.advance_window(ledger.time + 1e-6));  // at rest and unloaded: the ledger stays
  const SolverState& s = solver.state();
  std::printf("leaflet: floor %.3g J; after %lld steps the balance is %.3g of the largest energy %.3g J\n",
              solver.energy_check_floor(), static_cast<long long>(s.step - 1000), s.energy.balance_error_of_largest(),
              s.energy.largest_energy);
  EXPECT_GE(s.step, 1010);  // (ten steps of 0.1 us, the last split in two)
  EXPECT_GT(s.energy.balance_error_of_largest(), 0.2) << "without the floor this ledger would be stopped";
  EXPECT_GT(solver.energy_check_floor(), 1e3 * 8.6e-14);
  // What the progress lines print is judged against the floor, not the round-off-sized energies.
  EXPECT_NEAR(solver.energy_growth_measure(), std::abs(s.energy.balance()) / solver.energy_check_floor(), 1e-15);
  EXPECT_LT(solver.energy_growth_measure(), 1e-3);
}

TEST(EnergyGrowthStop, StableForcedStepClosesItsBalanceAndRuns) {
  const double critical = critical_step();
  auto solver = forced_run(0.9 * critical);
  EXPECT_NO_THROW(solver->advance_window(3000 * critical));
  const double error = solver->state().energy.balance_error_of_largest();
  std::printf("forced step 0.9 x 2/omega_max: %lld steps, balance %.3g of the largest energy\n",
              static_cast<long long>(solver->state().step), error);
  // Constant step: the ledger closes up to the telescoping half-kick term (omega dt)^2 / 4 of
  // the top mode's share of the energy, tiny for a smooth pressure load.
  EXPECT_LT(error, 1e-3);
}

// Session 10: the coupled 2D leaflet at mu = 20 (2D stability map, IQN-ILS) was stopped for energy
// growth with the loads' work at 1e-4 of the created energy: its 13 us windows held 2.25 stable
// steps, which the landing rule of the time made a repeating [dt, 0.62 dt, 0.62 dt] pattern, and
// averaged-step central differences with that period amplify modes at omega dt ~ 1.3, well under
// the constant-step limit 2 (spectral radius 1.21 per window). Equal steps to each window's end
// keep the unloaded, undamped plate's energy, in the same windows, and close its ledger.
// (Coupled windows only: FE-only output intervals keep the old rule, docs/solid_fe.md.)
TEST(EnergyGrowthStop, WindowsOfTwoAndAQuarterStepsKeepAnUndampedPlatesEnergy) {
  ShellSolver solver(plate_model(), SaintVenantKirchhoff(kYoungsModulus, kPoisson));
  const Eigen::Index n = solver.state().position.cols();
  Eigen::Matrix3Xd v(3, n);
  std::uint64_t seed = 88172645463325252ull;  // xorshift: every mode excited, deterministically
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    seed ^= seed << 13;
    seed ^= seed >> 7;
    seed ^= seed << 17;
    v.data()[i] = 1e-3 * (static_cast<double>(seed % 2001) / 1000.0 - 1.0);  // m/s
  }
  solver.set_velocity(v);
  solver.advance_window(0.0);
  const double window = 2.25 * solver.state().stable_step;
  const Eigen::Matrix3Xd no_load = Eigen::Matrix3Xd::Zero(3, n);
  // Full-step energies swing by up to (omega dt / 2)^2 of the top modes' share about the conserved
  // one: compare the largest in the first and the last 200 windows.
  double early = 0.0, late = 0.0;
  for (int w = 1; w <= 2000; ++w) {
    solver.advance_window(w * window, &no_load);
    const double e = solver.state().energy.kinetic + solver.state().energy.strain_energy;
    if (w <= 200) early = std::max(early, e);
    if (w > 1800) late = std::max(late, e);
  }
  const SolverState& s = solver.state();
  std::printf("windows of 2.25 stable steps: largest energy %.4g J (windows 1-200), %.4g J (1801-2000) after %lld "
              "steps (%.3g per window), balance %.3g of the largest energy\n",
              early, late, static_cast<long long>(s.step), static_cast<double>(s.step) / 2000.0,
              s.energy.balance_error_of_largest());
  EXPECT_EQ(s.step, 6000);  // three equal steps per window
  EXPECT_LT(std::abs(late / early - 1.0), 0.02);  // (the uneven pattern: x 1e9)
  EXPECT_LT(s.energy.balance_error_of_largest(), 0.1);
}

TEST(EnergyGrowthStop, ProgramStopsWithCodeThreeAndKeepsItsOutput) {
  const double critical = critical_step();
  const auto dir = std::filesystem::temp_directory_path() / "solid_energy_growth_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  write_mesh(dir / "plate.mesh.h5", plate_mesh());
  const double dp_mmHg = kPressure / 133.322387415;
  const double end = 3000 * critical;
  std::ofstream(dir / "case.textproto")
      << "run { end_time: " << end << " snapshot_interval: " << end / 4 << " series_interval: " << end / 100
      << " fe_only: true }\n"
      << "waveform { period_s: 0.8 time_s: [0, 0.4] ventricular_pressure_mmHg: [" << dp_mmHg << ", " << dp_mmHg
      << "] aortic_pressure_mmHg: [0, 0] }\n"
      << "solid { mesh_file: \"plate.mesh.h5\" material: SAINT_VENANT_KIRCHHOFF saint_venant_kirchhoff { "
         "youngs_modulus_kPa: "
      << kYoungsModulus * 1e-3 << " poisson_ratio: " << kPoisson << " } forced_time_step: " << 1.002 * critical
      << " }\n";
  const std::string command = std::string(SOLID_FE_EXECUTABLE) + " --case " + (dir / "case.textproto").string() +
                              " --output " + (dir / "out").string() + " > " + (dir / "log.txt").string() + " 2>&1";
  const int status = std::system(command.c_str());
  std::ifstream in(dir / "log.txt");
  const std::string log{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  ASSERT_TRUE(WIFEXITED(status)) << log;
  EXPECT_EQ(WEXITSTATUS(status), 3) << log;
  for (const char* part : {"energy growth at t =", "Kinetic energy's element: element", "% of the kinetic energy",
                           "the last sample and snapshot"}) {
    EXPECT_NE(log.find(part), std::string::npos) << part << " missing in: " << log;
  }
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "solid_fields.xdmf"));
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "solid_series.h5"));
}

}  // namespace
}  // namespace valvefsi::solid::testing

namespace valvefsi::solid::testing {
namespace {

// A closed-contact model of the diastolic leaflet: an undamped MHGO flap (10 x 5 mm, 100
// triangles) clamped along one edge and pushed by a steady 10 kPa follower pressure onto a rigid
// plane 0.3 mm below it, in output windows of 0.1 ms like the program's. Its free edge slams onto
// the plane and chatters on it (docs/solid_fe.md, "Diastolic energy growth"). With a constant
// step of 5 us the balance stays closed; with the default step control (element estimate,
// Lanczos calibration, growth limit) the chatter gains energy until the energy-growth stop ends
// the run: the penalty's on/off impacts at steps near the in-contact stability limit.
struct ChatterRun {
  double worst = 0.0;                // largest balance error of the largest energy, over the windows
  std::int64_t contact_changes = 0;  // windows after which the number of nodes in contact changed
  std::string stop;                  // the EnergyGrowthError's message, if the run was stopped
  double stopped_at = 0.0;
  std::int64_t hottest_node = -1;    // where the stop found the kinetic energy
};

double flap_pressure(double t) { return -10e3 * std::min(1.0, t / 1e-3); }  // 75 mmHg towards -z
const Plane kFlapPlane{Eigen::Vector3d(0, 0, -0.3e-3), Eigen::Vector3d(0, 0, 1)};

// look_ahead: solid.time_step_look_ahead (the case default is 2; 0 = the fifth session's control).
std::unique_ptr<ShellSolver> flap_solver(double fixed_step, double look_ahead = 2.0) {
  Mesh mesh = rectangular_plate(0.01, 0.005, 10, 5, 0.25e-3);
  ShellModelOptions options;
  options.fixed_nodes = mesh.node_sets.at("left");
  SolverOptions solver_options;
  solver_options.time_step_calibration_interval = 2000;  // the case defaults
  solver_options.max_time_step_growth = 0.002;
  solver_options.max_energy_balance_error = 0.2;
  solver_options.fixed_time_step = fixed_step;
  solver_options.time_step_look_ahead = look_ahead;
  auto solver = std::make_unique<ShellSolver>(build_shell_model(mesh, options), Material{Mhgo{}}, solver_options);
  solver->set_pressure(flap_pressure);
  solver->add_contact_plane(kFlapPlane);
  return solver;
}

ChatterRun chattering_flap(double fixed_step, double look_ahead = 2.0) {
  const auto flap = flap_solver(fixed_step, look_ahead);
  ShellSolver& solver = *flap;
  ChatterRun run;
  std::int64_t previous_contact = 0;
  try {
    for (int k = 1; k <= 300; ++k) {  // 30 ms
      solver.advance_window(k * 1e-4);
      run.worst = std::max(run.worst, solver.state().energy.balance_error_of_largest());
      if (solver.state().nodes_in_contact != previous_contact) ++run.contact_changes;
      previous_contact = solver.state().nodes_in_contact;
    }
  } catch (const EnergyGrowthError& e) {
    run.stop = e.what();
    run.stopped_at = solver.state().time;
    run.hottest_node = e.hottest_node();
  }
  std::printf("chattering flap, step %s (look-ahead %g): %lld steps to %.4g s, contact changed in %lld windows, "
              "balance error at most %.3g of the largest energy%s\n",
              fixed_step > 0 ? "constant" : "default control", look_ahead, static_cast<long long>(solver.state().step),
              solver.state().time, static_cast<long long>(run.contact_changes), run.worst,
              run.stop.empty() ? "" : ", stopped for energy growth");
  return run;
}

TEST(EnergyGrowthStop, FlapChatteringOnAPlaneAtAConstantStepKeepsItsBalance) {
  const ChatterRun run = chattering_flap(5e-6);
  EXPECT_TRUE(run.stop.empty()) << run.stop;
  EXPECT_GT(run.contact_changes, 100) << "the flap should chatter on the plane";
  EXPECT_LT(run.worst, 3e-2);  // measured 1.6e-2 (7 us: 4.2e-2; 10 us is unstable in contact)
}

// The default control (element estimate also taken one look-ahead of 2 steps along the current
// velocities, Lanczos calibration, growth limit) runs the chattering flap for 30 ms. Bound: the
// constant 5 us step, the old stable reference, reaches 4.3e-2 at its worst step in these 30 ms
// (1.6e-2 at window ends) and is itself stopped at 60.7 ms (docs/solid_fe.md, "The pressed flap");
// the default must stay below 5e-2 at window ends (measured 2.6e-2).
TEST(EnergyGrowthStop, FlapChatteringOnAPlaneWithTheDefaultStepKeepsItsBalance) {
  const ChatterRun run = chattering_flap(0.0);
  EXPECT_TRUE(run.stop.empty()) << run.stop;
  EXPECT_GT(run.contact_changes, 100) << "the flap should chatter on the plane";
  EXPECT_LT(run.worst, 5e-2);
}

// Without the look-ahead (the fifth session's control) the same flap is stopped: the free corner
// node, whose only triangle (element 18) whips outward, meets MHGO's exponential stiffening within
// one step (4 % fibre strain per step: the fibre stiffness x5 from one step to the next) after a
// step estimate taken at a softer instant.
TEST(EnergyGrowthStop, FlapChatteringOnAPlaneWithoutLookAheadIsStoppedAtTheWhippingCorner) {
  const ChatterRun run = chattering_flap(0.0, 0.0);
  ASSERT_FALSE(run.stop.empty()) << "the control without look-ahead no longer gains energy here: update the docs";
  EXPECT_GT(run.stopped_at, 5e-3);
  EXPECT_NE(run.stop.find("nodes in contact"), std::string::npos) << run.stop;
  EXPECT_EQ(run.hottest_node, grid_node(10, 0, 10)) << "the free corner held by one triangle";
}

// Is the default step above the pressed flap's critical step because the estimate misses the
// contact penalty's or the follower pressure's stiffness? No: at the chattering state (9 ms, 48-55
// nodes in contact) the dense M^-1 K of the free dofs with the internal, penalty and pressure
// (finite-difference, non-symmetric) terms has the same top frequency as the internal part
// alone to 1 % (measured 13.7 us both), and the step taken (11.5 us) is below 2/omega_max, though
// the element estimate (15.1 us) is above it (docs/solid_fe.md, "Diastolic energy growth").
TEST(EnergyGrowthStop, ContactAndPressureStiffnessDoNotLowerTheFlapsCriticalStep) {
  const auto solver = flap_solver(0.0, 0.0);
  for (int k = 1; k <= 90; ++k) solver->advance_window(k * 1e-4);  // the chatter run's windows (one 9 ms window blows up at 8.3 ms)
  const SolverState& s = solver->state();
  const SolverOptions& calibrating = solver->options();
  ElementModel& elements = const_cast<ElementModel&>(solver->elements());  // internal_force is non-const (work arrays)
  const Eigen::Index n = s.position.cols();
  std::vector<Eigen::Index> dofs;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!elements.fixed()[static_cast<std::size_t>(i)]) {
      for (Eigen::Index d = 0; d < 3; ++d) dofs.push_back(3 * i + d);
    }
  }
  const auto m = static_cast<Eigen::Index>(dofs.size());
  const auto forces = [&](const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& internal, Eigen::Matrix3Xd& pressure) {
    elements.internal_force(x, false, internal, nullptr);
    pressure.setZero(3, n);
    elements.add_pressure_force(x, flap_pressure(s.time), pressure);
  };
  Eigen::Matrix3Xd f0(3, n), p0(3, n), f1(3, n), p1(3, n);
  forces(s.position, f0, p0);
  Eigen::MatrixXd k_internal(m, m), k_pressure(m, m), k_contact = Eigen::MatrixXd::Zero(m, m);
  const double h = 1e-9;  // m, 4e-6 of the thickness
  for (Eigen::Index c = 0; c < m; ++c) {
    Eigen::Matrix3Xd x = s.position;
    x.data()[dofs[static_cast<std::size_t>(c)]] += h;
    forces(x, f1, p1);
    for (Eigen::Index r = 0; r < m; ++r) {
      const Eigen::Index dof = dofs[static_cast<std::size_t>(r)];
      k_internal(r, c) = (f1.data()[dof] - f0.data()[dof]) / h;
      k_pressure(r, c) = -(p1.data()[dof] - p0.data()[dof]) / h;
    }
  }
  const Eigen::VectorXd half_thickness = elements.contact_half_thickness();
  Eigen::VectorXd inverse_mass(m);
  int in_contact = 0;
  for (Eigen::Index r = 0; r < m; ++r) {
    const Eigen::Index dof = dofs[static_cast<std::size_t>(r)], node = dof / 3;
    inverse_mass(r) = 1.0 / elements.nodal_mass()(node);
    const double gap = (s.position.col(node) - kFlapPlane.point).dot(kFlapPlane.normal) - half_thickness(node);
    if (gap < 0.0 && dof % 3 == 2) {  // the penalty k = factor m omega_pen^2 along the plane's normal (z)
      k_contact(r, r) = calibrating.contact_stiffness_factor * elements.nodal_mass()(node) * s.contact_omega2;
      ++in_contact;
    }
  }
  const auto omega_max = [&](const Eigen::MatrixXd& k) {
    const Eigen::VectorXcd lambda = Eigen::EigenSolver<Eigen::MatrixXd>(inverse_mass.asDiagonal() * k).eigenvalues();
    return std::sqrt(lambda.cwiseAbs().maxCoeff());
  };
  const double internal = 2.0 / omega_max(k_internal);
  const double all = 2.0 / omega_max(k_internal + k_contact + k_pressure);
  const double step = s.stable_step / std::sqrt(1.0 + calibrating.contact_stiffness_factor);  // as taken
  const double element_estimate = s.stable_step / calibrating.time_step_safety / s.step_calibration;
  std::printf("flap at %.4g ms, %d nodes in contact: 2/omega_max internal %.3g us, with contact and pressure %.3g us; "
              "element estimate %.3g us (calibration x%.2f), step taken %.3g us\n",
              s.time * 1e3, in_contact, internal * 1e6, all * 1e6, element_estimate * 1e6, s.step_calibration, step * 1e6);
  ASSERT_GT(in_contact, 20) << "the flap should be pressed onto the plane";
  EXPECT_NEAR(all / internal, 1.0, 1e-2);
  EXPECT_LT(step, all) << "the control's step is above the linear critical step 2/omega_max";

  // Here the element estimate lies above 2/omega_max. The calibration (the last Lanczos 2/omega_max
  // scaled by the element estimate's fall since) may now lower the critical step below the element
  // estimate: the step used stays below the dense 2/omega_max. Clamped at the element estimate, as
  // before, it would lie above it.
  const double used = s.stable_step / calibrating.time_step_safety;
  std::printf("critical step used %.4g us (calibration x%.3f)\n", used * 1e6, s.step_calibration);
  ASSERT_GT(element_estimate, 1.03 * all) << "the element estimate is no longer above the flap's 2/omega_max here";
  EXPECT_LT(s.step_calibration, 1.0);
  EXPECT_LT(used, all);
}

}  // namespace
}  // namespace valvefsi::solid::testing
