// The coupled mode: the solid's mid-surface (3D) or strip front line (2D) is the interface; each
// coupling window the fluid's forces are applied, constant over the window, while the explicit
// solver sub-cycles to the window's end (or, with time_integration IMPLICIT in 3D, generalized-alpha
// steps land on it: its numerical damping takes out modes faster than the window, which the fluid
// cannot damp). Checkpoints are copies of the solver state. The case's waveform is not applied:
// the fluid carries the load.
#include "participant_mode.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>

#include <omp.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "valvefsi/coupling/endpoint.hpp"
#include "valvefsi/coupling/participant.hpp"
#include "valvefsi/coupling/restart_file.hpp"
#include "valvefsi/solid/case_setup.hpp"
#include "valvefsi/solid/energy_growth_error.hpp"
#include "valvefsi/solid/energy_growth_report.hpp"
#include "valvefsi/solid/material_error.hpp"
#include "valvefsi/solid/solid_interface.hpp"
#include "valvefsi/solid/solid_output.hpp"
#include "valvefsi/solid/solver_restart.hpp"

namespace valvefsi::solid {
namespace {

using Clock = std::chrono::steady_clock;
constexpr int kExitSolidFailure = 6;  // the solid's own failure (material state, energy growth), after an Abort

// Output at accepted window ends: with an implicit scheme a window is accepted only when the
// next one does not restore it, so the state is written when the following window opens.
class CoupledOutput {
 public:
  CoupledOutput(const cases::Case& c, const std::filesystem::path& dir, const SolidSetup& setup,
                const std::string& suffix)
      : fields_(dir, setup.mesh, setup.element_family, suffix), series_(dir, monitors_of(setup), suffix),
        snapshot_interval_(c.run().snapshot_interval()), series_interval_(c.run().series_interval()) {}

  void accepted(const ExplicitSolver& solver, bool last) {
    const double t = solver.state().time;
    if (t >= next_sample_ - 1e-12 || last || samples_ == 0) {
      series_.sample(solver, 0.0);  // no prescribed pressure in coupled mode
      ++samples_;
      next_sample_ = series_interval_ > 0 ? (std::floor(t / series_interval_ + 1e-9) + 1) * series_interval_ : t;
    }
    if (snapshot_interval_ > 0 && (t >= next_snapshot_ - 1e-12 || last || fields_.count() == 0)) {
      double peak_stress = 0, peak_strain = 0;
      fields_.write(solver, peak_stress, peak_strain);
      series_.add_snapshot_peaks(t, peak_stress, peak_strain);
      next_snapshot_ = (std::floor(t / snapshot_interval_ + 1e-9) + 1) * snapshot_interval_;
      series_.flush();
    }
    if (last) series_.flush();
  }
  // A peer's stop: the samples taken since the last snapshot go to disk too (the state itself may
  // be an iterate the coupler never accepted, so it is not sampled).
  void flush() { series_.flush(); }

 private:
  static std::vector<std::pair<std::string, std::vector<std::int64_t>>> monitors_of(const SolidSetup& setup) {
    std::vector<std::pair<std::string, std::vector<std::int64_t>>> m;
    for (const auto& s : setup.monitors) m.emplace_back(s.name, s.nodes);
    return m;
  }
  FieldWriter fields_;
  SeriesWriter series_;
  double snapshot_interval_, series_interval_;
  double next_sample_ = 0, next_snapshot_ = 0;
  int samples_ = 0;
};

coupling::InterfaceSurfaceData surface_data(const SolidInterface& s) {
  coupling::InterfaceSurfaceData d;
  d.positions = s.positions;
  d.nodes_per_cell = s.nodes_per_cell;
  d.cells = s.cells;
  d.node_areas = s.node_areas;
  d.node_thickness = s.node_thickness;
  return d;
}

}  // namespace

int run_participant(const cases::Case& c, const std::filesystem::path& case_file,
                    const std::filesystem::path& output_dir) {
  const auto wall_start = Clock::now();
  check_coupled_solid_case(c, case_file);
  SolidSetup setup = setup_from_case(c, case_file);
  for (const auto& note : setup.notes) spdlog::info("{}", note);
  ExplicitSolver& solver = *setup.solver;
  if (solver.implicit()) {
    spdlog::info("coupled solid: implicit generalized-alpha steps (rho_inf = {}) of at most {:.3g} s, landing on "
                 "each window's end", solver.options().spectral_radius_infinity, solver.options().max_time_step);
  }
  const SolidInterface interface =
      setup.dimension == 2 ? strip_interface(setup.mesh, setup.strip_ties, setup.strip_depth, setup.mesh_file.string())
      : setup.element_family == ElementFamily::hexahedron
          ? brick_mid_surface_interface(setup.mesh, setup.mesh_file.string())
          : surface_interface(setup.mesh);

  coupling::ParticipantOptions options;
  options.role = coupling::ParticipantRole::solid;
  options.solver_name = "solid_fe";
  options.solver_version = "0.2.0";
  options.endpoint = coupling::resolve_endpoint(c.coupling().endpoint(), output_dir);
  options.spatial_dimension = setup.dimension;
  options.can_checkpoint = true;
  options.can_restart = true;  // solver_restart.hpp: the whole SolverState
  options.liveness.heartbeat_interval = std::chrono::duration<double>(c.coupling().heartbeat_interval_s());
  options.liveness.peer_timeout = std::chrono::duration<double>(c.coupling().peer_timeout_s());
  options.liveness.startup_timeout = std::chrono::duration<double>(c.coupling().startup_timeout_s());

  std::unique_ptr<coupling::Participant> participant;
  std::optional<CoupledOutput> output;
  try {
    participant = std::make_unique<coupling::Participant>(options);
    if (solver.automatic()) {
      // The switch reads the case's pressure waveform, which a coupled run does not apply. (Thrown
      // after the participant exists, so that the coupler and the fluid are told at once.)
      throw std::runtime_error(fmt::format("{}: field 'solid.time_integration' = AUTOMATIC in a coupled run: allowed "
                                           "only with --fe-only (coupled runs use EXPLICIT or IMPLICIT)",
                                           case_file.string()));
    }
    solver.advance_window(0.0);  // forces and stable step of the initial state
    coupling::InterfaceMotion motion;
    interface.motion(solver.state(), motion.positions, motion.velocities);
    participant->initialize_solid(surface_data(interface), motion);
    std::string output_suffix;
    if (const auto& folder = participant->session().restart_directory; !folder.empty()) {
      const auto file = coupling::restart_file_path(folder, participant->name());
      read_solver_restart(file, solver);
      const double t = participant->session().restart_time;
      if (std::abs(solver.state().time - t) > 1e-9 * std::max(1.0, std::abs(t))) {
        throw std::runtime_error(fmt::format("{}: the solid's state is at t = {} s, the coupler restarts at {} s",
                                             file.string(), solver.state().time, t));
      }
      output_suffix = restarted_output_suffix(output_dir, t);
      spdlog::info("continuing from {} (t = {} s, step {}); output {}", file.string(), solver.state().time,
                   solver.state().step, output_suffix.empty() ? "files start at the restart time"
                                                              : "files named with suffix " + output_suffix);
    }
    output.emplace(c, output_dir, setup, output_suffix);
    spdlog::info("coupled ({}D, {} interface nodes, {} cells) with {} {}, scheme {}; {} threads; output to {}",
                 setup.dimension, interface.nodes.size(), interface.cells.cols(),
                 participant->session().partner_solver_name, participant->session().partner_solver_version,
                 participant->session().scheme, omp_get_max_threads(), output_dir.string());

    std::optional<SolverState> checkpoint;
    Eigen::Matrix3Xd nodal_forces;
    coupling::Window window;
    bool have_unwritten_state = true;  // the initial state
    std::uint64_t repeats = 0;
    auto last_progress = Clock::now();
    while (participant->next_window(window)) {
      if (window.restore_checkpoint) {
        if (!checkpoint) throw std::logic_error("the coupler asked to restore a checkpoint never saved");
        solver.restore(*checkpoint);
        ++repeats;
      } else if (have_unwritten_state) {
        output->accepted(solver, false);
      }
      if (window.save_checkpoint) checkpoint = solver.state();
      if (window.write_restart) {
        write_solver_restart(solver, coupling::restart_file_path(window.restart_directory, participant->name()));
      }
      interface.nodal_forces(window.loads.forces, setup.mesh.num_nodes(), nodal_forces);
      try {
        solver.advance_window(window.end(), &nodal_forces);
      } catch (const EnergyGrowthError& e) {
        // Write the state of the failing step as the last output, then stop as for a material failure.
        output->accepted(solver, true);
        throw EnergyGrowthError(fmt::format("{} Kinetic energy's element: {}. The last sample and snapshot of {} hold "
                                            "this state.", e.what(),
                                            kinetic_energy_element(setup.mesh, setup.element_family, solver,
                                                                   e.hottest_node()),
                                            output_dir.string()),
                                e.hottest_node());
      }
      have_unwritten_state = true;
      interface.motion(solver.state(), motion.positions, motion.velocities);
      participant->complete_window(motion, 0.0);  // the explicit solid sub-cycles: any window is stable

      const auto now = Clock::now();
      if (std::chrono::duration<double>(now - last_progress).count() >= c.solid().progress_interval_s()) {
        last_progress = now;
        const SolverState& s = solver.state();
        spdlog::info("t = {:.5f} s, window {} (iteration {}), step {}, dt = {:.3g} s, energy check {:.2e}, wall {:.1f} s",
                     s.time, window.index, window.iteration, s.step, s.stable_step,
                     solver.energy_growth_measure(),
                     std::chrono::duration<double>(now - wall_start).count());
      }
    }
    output->accepted(solver, true);
    const SolverState& s = solver.state();
    const double wall = std::chrono::duration<double>(Clock::now() - wall_start).count();
    spdlog::info("done: t = {} s, {} steps, {} repeated windows, wall time {:.1f} s ({:.3g} ms per step), "
                 "energy balance error {:.2e}",
                 s.time, s.step, repeats, wall, 1e3 * wall / std::max<std::int64_t>(s.step, 1),
                 s.energy.relative_balance_error());
    spdlog::info("coupler loads: work {:.6e} J on the solid (F . dx), {:.6e} J as the coupler books it "
                 "(F . v(window start) dt)", s.energy.external_work, s.energy.interface_work);
    participant->finalize();
    return 0;
  } catch (const coupling::TransportError& e) {
    spdlog::error("{}", e.what());
    if (output) output->flush();
    if (participant) participant->abort(e.what());
    return e.exit_code();
  } catch (const EnergyGrowthError& e) {
    spdlog::error("{}", e.what());
    if (participant) participant->abort(std::string("solid_fe: ") + e.what());
    return kExitSolidFailure;
  } catch (const MaterialStateError& e) {
    spdlog::error("{}", e.what());
    if (output) output->flush();
    if (participant) participant->abort(std::string("solid_fe: ") + e.what());
    return kExitSolidFailure;
  } catch (const std::runtime_error& e) {  // e.g. a restart file that does not fit this case
    spdlog::error("{}", e.what());
    if (output) output->flush();
    if (participant) participant->abort(std::string("solid_fe: ") + e.what());
    return 2;
  }
}

}  // namespace valvefsi::solid
