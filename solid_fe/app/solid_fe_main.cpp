// solid_fe: the leaflet finite-element solver. FE-only mode applies the case's uniform
// transvalvular pressure to the leaflets and runs to run.end_time; otherwise it is the
// coupler's structure participant (participant_mode.cpp, docs/solid_fe.md).
//   solid_fe --case cases/<name>.textproto [--fe-only] [--output DIR] [--restart DIR]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <omp.h>
#include <spdlog/spdlog.h>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/case/pressure_waveform.hpp"
#include "valvefsi/coupling/restart_file.hpp"
#include "valvefsi/coupling/restart_points.hpp"
#include "valvefsi/solid/case_setup.hpp"
#include "valvefsi/solid/energy_growth_error.hpp"
#include "valvefsi/solid/energy_growth_report.hpp"
#include "valvefsi/solid/material_error.hpp"
#include "valvefsi/solid/solid_output.hpp"
#include "valvefsi/solid/solver_restart.hpp"
#include "participant_mode.hpp"

namespace {

using Clock = std::chrono::steady_clock;

// Index of the first multiple of `interval` after t (a restarted run continues the same grid).
std::int64_t next_multiple(double t, double interval) {
  return interval > 0 ? static_cast<std::int64_t>(std::floor(t / interval + 1e-9)) + 1 : 1;
}

int run_fe_only(const valvefsi::cases::Case& c, const std::filesystem::path& case_file,
                const std::filesystem::path& output_dir, const std::string& restart) {
  using namespace valvefsi::solid;
  const auto wall_start = Clock::now();
  SolidSetup setup = setup_from_case(c, case_file);
  for (const auto& note : setup.notes) spdlog::info("{}", note);
  const valvefsi::PressureWaveform waveform(c.waveform(), case_file.string());
  ExplicitSolver& solver = *setup.solver;
  solver.set_pressure_waveform([&waveform](double t) { return waveform.transvalvular_pressure(t); });

  const double end_time = c.run().end_time();
  const double snapshot_interval = c.run().snapshot_interval();
  const double series_interval = c.run().series_interval();
  std::vector<std::pair<std::string, std::vector<std::int64_t>>> monitors;
  for (const auto& m : setup.monitors) monitors.emplace_back(m.name, m.nodes);
  solver.advance_window(0.0);
  std::string suffix;
  if (!restart.empty()) {
    const auto folder = valvefsi::coupling::resolve_restart_folder(restart, {"solid"});
    read_solver_restart(valvefsi::coupling::restart_file_path(folder, "solid"), solver);
    suffix = restarted_output_suffix(output_dir, solver.state().time);
    spdlog::info("continuing from {} (t = {} s, step {}); output {}", folder.string(), solver.state().time,
                 solver.state().step, suffix.empty() ? "files start at the restart time" : "files named with suffix " + suffix);
  }
  FieldWriter fields(output_dir, setup.mesh, setup.element_family, suffix);
  SeriesWriter series(output_dir, monitors, suffix);
  spdlog::info("FE-only: {} s of the waveform on {} threads, output to {}", end_time, omp_get_max_threads(),
               output_dir.string());

  const auto snapshot = [&] {
    double peak_stress = 0, peak_strain = 0;
    fields.write(solver, peak_stress, peak_strain);
    series.add_snapshot_peaks(solver.state().time, peak_stress, peak_strain);
  };
  const auto sample = [&] { series.sample(solver, waveform.transvalvular_pressure(solver.state().time)); };

  // Output times and restart points are the windows the solver advances over.
  const double restart_interval = c.solid().restart_interval_s();
  const double t0 = solver.state().time;
  std::int64_t next_snapshot = next_multiple(t0, snapshot_interval), next_sample = next_multiple(t0, series_interval);
  std::int64_t next_restart = next_multiple(t0, restart_interval);
  const auto time_of = [](std::int64_t k, double interval) { return interval > 0 ? k * interval : HUGE_VAL; };
  if (snapshot_interval > 0) snapshot();
  sample();
  auto last_progress = Clock::now();
  const double progress_interval = c.solid().has_progress_interval_s() ? c.solid().progress_interval_s() : 10.0;
  int status = 0;
  try {
    while (solver.state().time < end_time) {
      const double t_snap = time_of(next_snapshot, snapshot_interval);
      const double t_sample = series_interval > 0 ? time_of(next_sample, series_interval) : solver.state().time + 1e-4;
      const double t_restart = time_of(next_restart, restart_interval);
      const double target = std::min({end_time, t_snap, t_sample, t_restart});
      solver.advance_window(target);
      const double t = solver.state().time;
      if (t >= t_restart - 1e-12) {
        const auto folder = valvefsi::coupling::restart_folder(output_dir, t);
        std::filesystem::create_directories(folder);
        write_solver_restart(solver, valvefsi::coupling::restart_file_path(folder, "solid"));
        solver.drop_kept_tangent();  // as the run continued from this file will (bit for bit)
        valvefsi::coupling::mark_restart_complete(folder, c.solid().restart_keep());
        ++next_restart;
      }
      if (t >= t_sample - 1e-12 || t >= end_time) {
        sample();
        ++next_sample;
      }
      if (snapshot_interval > 0 && (t >= t_snap - 1e-12 || t >= end_time)) {
        snapshot();
        ++next_snapshot;
        series.flush();
      }
      const auto now = Clock::now();
      if (std::chrono::duration<double>(now - last_progress).count() >= progress_interval || t >= end_time) {
        last_progress = now;
        const double wall = std::chrono::duration<double>(now - wall_start).count();
        const SolverState& s = solver.state();
        spdlog::info("t = {:.5f} s ({:.1f} %), step {}, dt = {:.3g} s (element {}, calibration x{:.2f}), "
                     "energy check {:.2e}, wall {:.1f} s, left ~{:.0f} s",
                     t, 100 * t / end_time, s.step, s.stable_step, s.critical_element, s.step_calibration,
                     solver.energy_growth_measure(), wall, wall * (end_time - t) / std::max(t - t0, 1e-12));
      }
    }
  } catch (const MaterialStateError& e) {
    spdlog::error("{}", e.what());
    spdlog::error("stopping at t = {} s; the output holds the state up to the last completed window",
                  solver.state().time);
    status = 3;
  } catch (const EnergyGrowthError& e) {
    // The state is that of a completed step: write it as the last sample and snapshot.
    spdlog::error("{} Kinetic energy's element: {}.", e.what(),
                  kinetic_energy_element(setup.mesh, setup.element_family, solver, e.hottest_node()));
    sample();
    if (snapshot_interval > 0) snapshot();
    spdlog::error("stopping at t = {} s; the last sample and snapshot of {} hold this state", solver.state().time,
                  output_dir.string());
    status = 3;
  }
  series.flush();
  const double wall = std::chrono::duration<double>(Clock::now() - wall_start).count();
  const SolverState& s = solver.state();
  spdlog::info("done: t = {} s, {} steps, wall time {:.1f} s ({:.3g} ms per step), energy balance error {:.2e}",
               s.time, s.step, wall, 1e3 * wall / std::max<std::int64_t>(s.step, 1),
               s.energy.relative_balance_error());
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"solid_fe: leaflet finite-element solver (FE-only, or the coupler's structure participant)"};
  std::string case_path, output;
  bool fe_only = false;
  app.add_option("--case", case_path, "case file (protobuf text format, message valvefsi.cases.Case)")->required();
  app.add_flag("--fe-only", fe_only, "run alone under the case's uniform transvalvular pressure (default: coupled participant)");
  app.add_option("--output", output, "output folder (default: the case's run.output_dir)");
  std::string restart;
  app.add_option("--restart", restart,
                 "FE-only: continue from a restart point (a run's restart/ folder: its LATEST; or one t_<time> folder)");
  CLI11_PARSE(app, argc, argv);
  spdlog::set_pattern("[solid] %v");
  try {
    const valvefsi::cases::Case c = valvefsi::load_case(case_path);
    const std::filesystem::path output_dir = std::filesystem::path(output.empty() ? c.run().output_dir() : output);
    if (!fe_only && !c.run().fe_only()) {
      if (!restart.empty()) {
        spdlog::error("--restart {}: coupled runs restart through the coupler (run_case.py --restart), not solid_fe",
                      restart);
        return 2;
      }
      return valvefsi::solid::run_participant(c, case_path, output_dir);
    }
    return run_fe_only(c, case_path, output_dir, restart);
  } catch (const valvefsi::CaseError& e) {
    spdlog::error("{}", e.what());
    return 2;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
