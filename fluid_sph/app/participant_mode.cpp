#include "participant_mode.hpp"

#include <omp.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "mpi_world.hpp"
#include "run_output.hpp"
#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/coupling/endpoint.hpp"
#include "valvefsi/coupling/participant.hpp"
#include "valvefsi/coupling/restart_file.hpp"
#include "valvefsi/fluid/case_setup.hpp"
#include "valvefsi/fluid/coupling_window.hpp"
#ifdef VALVEFSI_FLUID_HAS_THIN_WALL
#include "valvefsi/fluid/thin_wall/thin_wall_model.hpp"
#include "valvefsi/fluid/thin_wall/thin_wall_model_3d.hpp"
#endif

namespace valvefsi::fluid::app {
namespace {

// The surface model for the solid's interface (the two-sided thin wall: segments in 2D,
// triangles in 3D); throws std::invalid_argument naming what is missing when the fluid cannot
// represent this surface.
template <int D>
std::unique_ptr<ImmersedSurfaceModel<D>> surface_model(const coupling::InterfaceSurfaceData& surface,
                                                       const FluidSettings<D>& settings, const cases::Case& c,
                                                       const std::filesystem::path& case_file) {
#ifndef VALVEFSI_FLUID_HAS_THIN_WALL
  (void)surface, (void)settings, (void)c;
  throw std::invalid_argument(case_file.string() + ": fluid_sph was built without the thin-wall model "
                              "(fluid_sph/thin_wall), which couples a leaflet surface");
#else
  if (surface.nodes_per_cell != D)
    throw std::invalid_argument(fmt::format("{}: the solid's interface has {} nodes per cell; a {}D fluid needs {} ({})",
                                            case_file.string(), surface.nodes_per_cell, D, D, D == 2 ? "segments" : "triangles"));
  ImmersedSurfaceGeometry<D> geometry;
  const auto n = static_cast<std::size_t>(surface.positions.cols());
  geometry.nodes.resize(n);
  for (std::size_t j = 0; j < n; ++j)
    for (int d = 0; d < D; ++d) geometry.nodes[j][static_cast<std::size_t>(d)] = surface.positions(d, static_cast<Eigen::Index>(j));
  geometry.nodes_per_cell = D;
  geometry.cells.reserve(static_cast<std::size_t>(surface.cells.size()));
  for (Eigen::Index cell = 0; cell < surface.cells.cols(); ++cell)
    for (Eigen::Index k = 0; k < D; ++k) geometry.cells.push_back(static_cast<std::uint32_t>(surface.cells(k, cell)));
  geometry.node_thickness.assign(surface.node_thickness.data(), surface.node_thickness.data() + surface.node_thickness.size());
  if constexpr (D == 2)
    return thin_wall::make_thin_wall_model_2d(geometry, settings, c.fluid().thin_walls());
  else
    return thin_wall::make_thin_wall_model_3d(geometry, settings, c.fluid().thin_walls());
#endif
}

// Whether the surface model this case would build can write restart state: a model built on a
// one-cell stand-in geometry is asked (the capability must be declared before the real surface
// arrives with the handshake). The reason goes to the log when it cannot.
template <int D>
bool surface_model_can_restart(const FluidSettings<D>& settings, const cases::Case& c, const std::filesystem::path& case_file) {
  if (c.fluid().interface_model() == cases::FluidCase::NONE) return true;
  try {
    coupling::InterfaceSurfaceData probe;
    probe.nodes_per_cell = D;
    probe.positions = Eigen::Matrix3Xd::Zero(3, D);  // node j > 0 one spacing from node 0 along axis j - 1
    for (int j = 0; j < D; ++j)
      for (int d = 0; d < D; ++d)
        probe.positions(d, j) = 0.5 * (settings.domain_lower[d] + settings.domain_upper[d]) +
                                (j == d + 1 ? settings.particle_spacing : 0.0);
    probe.cells.resize(D, 1);
    for (int j = 0; j < D; ++j) probe.cells(j, 0) = j;
    probe.node_thickness = Eigen::VectorXd::Constant(D, 0.25 * settings.particle_spacing);
    probe.node_areas = Eigen::VectorXd::Constant(D, settings.particle_spacing);
    if (surface_model<D>(probe, settings, c, case_file)->restart_state()) return true;
    spdlog::info("fluid_sph: no restart capability: the immersed-surface model cannot write its restart state");
  } catch (const std::exception& e) {
    spdlog::info("fluid_sph: no restart capability: the immersed-surface model could not be asked ({})", e.what());
  }
  return false;
}

// Restart files hold the solver's named arrays and, under "array_names", their names (one
// character code per value, '\n' between names) so the reader needs no listing of the file.
void write_restart_file(const std::filesystem::path& file, const std::vector<NamedArray>& arrays) {
  coupling::RestartWriter writer(file);
  std::vector<double> names;
  for (const auto& a : arrays) {
    writer.put(a.name, std::span<const double>(a.values));
    for (const char ch : a.name) names.push_back(static_cast<double>(static_cast<unsigned char>(ch)));
    names.push_back('\n');
  }
  writer.put("array_names", std::span<const double>(names));
  writer.commit();
}

std::vector<NamedArray> read_restart_file(const std::filesystem::path& file) {
  const coupling::RestartReader reader(file);
  std::vector<NamedArray> arrays;
  std::string name;
  for (const double code : reader.doubles("array_names")) {
    if (code == '\n') {
      arrays.push_back(NamedArray{name, reader.doubles(name)});
      name.clear();
    } else {
      name.push_back(static_cast<char>(code));
    }
  }
  return arrays;
}

// Rank 0 writes <folder>/fluid.restart.h5 (the file the coupler's folder holds for the fluid);
// rank k > 0 of a split run its own particles to fluid.rank<k>.restart.h5 next to it.
std::filesystem::path rank_restart_file(const std::string& folder, const MpiWorld& world) {
  const auto file = coupling::restart_file_path(folder, "fluid");
  if (world.root()) return file;
  return file.parent_path() / fmt::format("fluid.rank{}.restart.h5", world.rank);
}

// Restart-file entry of the program (not the solver): the last window's total interface force.
constexpr std::string_view kLastInterfaceForce = "app/last_interface_force";

// What rank 0 learns from the coupler for a window, passed on to the other ranks.
struct WindowOrder {
  double more = 0, time = 0, size = 0, restore = 0, save = 0, write_restart = 0;
};

template <int D>
int run_coupled(const cases::Case& c, const std::filesystem::path& case_file, const std::filesystem::path& output) {
  coupling::ParticipantOptions options;
  options.role = coupling::ParticipantRole::fluid;
  options.solver_name = "fluid_sph";
  options.solver_version = "0.2.0";
  options.endpoint = coupling::resolve_endpoint(c.coupling().endpoint(), output);
  options.spatial_dimension = D;
  options.can_checkpoint = true;
  options.liveness.heartbeat_interval = std::chrono::duration<double>(c.coupling().heartbeat_interval_s());
  options.liveness.peer_timeout = std::chrono::duration<double>(c.coupling().peer_timeout_s());
  options.liveness.startup_timeout = std::chrono::duration<double>(c.coupling().startup_timeout_s());

  std::unique_ptr<coupling::Participant> participant;
  const MpiWorld world = mpi_world();
  try {
    const bool with_surface = c.fluid().interface_model() != cases::FluidCase::NONE;
    if (world.split() && with_surface)
      throw std::invalid_argument(fmt::format("{}: fluid_sph on {} MPI ranks needs fluid.interface_model: NONE (a leaflet "
                                              "in the fluid runs on one rank only); run it without mpirun",
                                              case_file.string(), world.size));
    auto setup = fluid_setup_from_case<D>(c, case_file);
    const ProbeSet<D> probes = setup.probes;
    const std::size_t plate_count = setup.plates.size();
    FluidSolver<D> solver = make_solver<D>(std::move(setup));
    if (world.split()) solver.decompose(MPI_COMM_WORLD);
    solver.compute_body_forces_every_step(probes.wall_forces);
    options.can_restart = surface_model_can_restart<D>(solver.settings(), c, case_file);
    if (world.root()) participant = std::make_unique<coupling::Participant>(options);

    std::size_t node_count = 0;
    if (world.root()) participant->initialize_fluid([&](const coupling::InterfaceSurfaceData& surface) {
      if (with_surface) solver.set_immersed_surface(surface_model<D>(surface, solver.settings(), c, case_file));
      node_count = static_cast<std::size_t>(surface.positions.cols());
      coupling::InterfacePoints points;
      points.positions = surface.positions;  // the fluid's loads are at the surface nodes
      points.areas = surface.node_areas;
      return points;
    });
    const std::size_t fluid_count = count_over_ranks(solver, Kind::fluid), wall_count = count_over_ranks(solver, Kind::wall);
    if (world.root())
      spdlog::info("fluid_sph: coupled ({}D) with {} {}, scheme {}: {} fluid + {} wall particles, {} interface nodes, "
                   "dp = {} m, c0 = {} m/s, {} plate(s), {} OpenMP thread(s) x {} MPI rank(s)",
                   D, participant->session().partner_solver_name, participant->session().partner_solver_version,
                   participant->session().scheme, fluid_count, wall_count, node_count, solver.settings().particle_spacing,
                   solver.settings().sound_speed, plate_count, omp_get_max_threads(), world.size);
    if (!with_surface) spdlog::info("fluid_sph: fluid.interface_model NONE: the solid's surface is not in the fluid; zero loads are sent");
    Vec<D> last_total{};
    std::string restart_directory = world.root() ? participant->session().restart_directory : std::string();
    double restart_time = world.root() ? participant->session().restart_time : 0.0;
    broadcast(world, restart_directory);
    broadcast(world, &restart_time, 1);
    if (!restart_directory.empty()) {
      const auto file = rank_restart_file(restart_directory, world);
      const std::vector<NamedArray> arrays = read_restart_file(file);
      solver.load_restart_state(arrays);
      // The program's own part: the last window's total interface force (the series' next row).
      for (const auto& a : arrays)
        if (a.name == kLastInterfaceForce && a.values.size() == D)
          for (int d = 0; d < D; ++d) last_total[d] = a.values[static_cast<std::size_t>(d)];
      if (std::abs(solver.time() - restart_time) > 1e-9 * std::max(1.0, solver.time()))
        throw std::runtime_error(fmt::format("{}: the fluid's state is at t = {} s, the coupler restarts at t = {} s", file.string(),
                                             solver.time(), restart_time));
      spdlog::info("fluid_sph: continuing from {} at t = {} s, step {}", file.string(), solver.time(), solver.step_count());
    }

    RunOutput<D> run_output(probes, plate_count, true, output, c.run().end_time(), c.run().snapshot_interval(),
                            c.run().series_interval(), world.root());
    ImmersedSurfaceModel<D>* model = solver.immersed_surface();
    std::vector<Vec<D>> end_positions(node_count), end_velocities(node_count);
    coupling::InterfaceLoads loads{Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(node_count))};
    coupling::Window window;
    std::uint64_t repeats = 0;
    const bool fit_window = c.fluid().fit_coupling_window_to_steps();
    CouplingWindowFitter window_fitter(c.coupling().window_size());
    const long first_step = solver.step_count();
    bool unwritten = true;  // the initial state
    while (true) {
      WindowOrder order;
      if (world.root()) {
        order.more = participant->next_window(window) ? 1 : 0;
        order.time = window.time;
        order.size = window.size;
        order.restore = window.restore_checkpoint;
        order.save = window.save_checkpoint;
        order.write_restart = window.write_restart;
      }
      broadcast(world, &order.more, 6);
      if (order.more == 0) break;
      if (!world.root()) {
        window.time = order.time;
        window.size = order.size;
        window.restore_checkpoint = order.restore != 0;
        window.save_checkpoint = order.save != 0;
        window.write_restart = order.write_restart != 0;
      }
      if (window.write_restart) broadcast(world, window.restart_directory);
      if (window.restore_checkpoint) {
        solver.restore_checkpoint();
        ++repeats;
      } else if (unwritten) {
        run_output.write_due(solver, last_total);  // the state the last window ended in is accepted
      }
      if (window.save_checkpoint) solver.save_checkpoint();
      if (window.write_restart) {
        auto state = solver.restart_state();
        if (!state) throw std::runtime_error("the coupler asked for restart state, but the immersed-surface model cannot write it");
        state->push_back(NamedArray{std::string(kLastInterfaceForce), std::vector<double>(last_total.begin(), last_total.end())});
        write_restart_file(rank_restart_file(window.restart_directory, world), *state);
        run_output.flush();  // a run continued from this point then has every probe sample before it
      }
      if (std::abs(solver.time() - window.time) > 1e-6 * window.size + 1e-12)
        throw std::runtime_error(fmt::format("fluid_sph: the coupler opened a window at t = {} s but the fluid is at t = {} s",
                                             window.time, solver.time()));
      // The coupler sends the markers at the window's start and their constant velocity.
      for (std::size_t j = 0; j < node_count; ++j) {
        const auto col = static_cast<Eigen::Index>(j);
        for (int d = 0; d < D; ++d) {
          end_velocities[j][d] = window.motion.velocities(d, col);
          end_positions[j][d] = window.motion.positions(d, col) + window.size * window.motion.velocities(d, col);
        }
      }
      if (model != nullptr) model->set_window_target(window.end(), end_positions, end_velocities);
      solver.reset_surface_force_average();
      const long window_first_step = solver.step_count();
      try {
        solver.advance_to(window.end());
      } catch (const FluidStop&) {
        run_output.write_last_state(solver, last_total);  // every rank sees the collapse (the step is common)
        throw;
      }
      const std::vector<Vec<D>> forces = solver.surface_force_average();
      last_total = Vec<D>{};
      for (std::size_t j = 0; j < forces.size(); ++j)  // none without a surface model: zero loads
        for (int d = 0; d < D; ++d) {
          loads.forces(d, static_cast<Eigen::Index>(j)) = forces[j][d];
          last_total[d] += forces[j][d];
        }
      // The fluid sub-cycles, so any window is stable; fitted, the next one holds whole steps.
      const double proposal = fit_window ? window_fitter.propose(solver.time_step(), solver.step_count() - window_first_step) : 0.0;
      if (world.root()) participant->complete_window(loads, proposal);
      unwritten = true;
    }
    run_output.write_due(solver, last_total);
    run_output.flush();
    const ImmersedSurfaceCounters counters = model != nullptr ? model->counters() : ImmersedSurfaceCounters{};
    const double wall = run_output.elapsed();
    const double updates = particles_over_ranks(solver) * static_cast<double>(solver.step_count() - first_step);
    spdlog::info("fluid_sph: done, t = {} s in {} steps, {} repeated windows, wall time {:.1f} s ({:.3g} particle updates/s), "
                 "{} particle(s) lost ({} by density), interface: {} put back, {} leaks, {} shifts refused; output in {}",
                 solver.time(), solver.step_count(), repeats, wall, updates / std::max(wall, 1e-9), solver.lost_count(),
                 solver.density_out_of_range_count(), counters.corrections, counters.leaks, counters.rejected_shifts,
                 output.string());
    if (fit_window)
      spdlog::info("fluid_sph: windows fitted to whole steps (fluid.fit_coupling_window_to_steps): {:.3f} steps per "
                   "window, {} window(s) overran their plan, step margin now {:.3f}",
                   window_fitter.mean_steps_per_window(), window_fitter.overruns(), window_fitter.margin());
    if (world.root()) participant->finalize();
    return 0;
  } catch (const coupling::TransportError& e) {
    spdlog::error("fluid_sph: {}", e.what());
    if (participant) participant->abort(e.what());
    return e.exit_code();
  } catch (const CaseError& e) {
    spdlog::error("{}", e.what());
    if (participant) participant->abort(std::string("fluid_sph: ") + e.what());
    return coupling::kExitBadInput;
  } catch (const std::invalid_argument& e) {
    spdlog::error("fluid_sph: {}", e.what());
    if (participant) participant->abort(std::string("fluid_sph: ") + e.what());
    return coupling::kExitBadInput;
  } catch (const std::exception& e) {
    spdlog::error("fluid_sph: {}", e.what());
    if (participant) participant->abort(std::string("fluid_sph: ") + e.what());
    return 1;
  }
}

}  // namespace

int run_participant(const cases::Case& c, const std::filesystem::path& case_file, const std::filesystem::path& output) {
  return c.run().dimension() == 2 ? run_coupled<2>(c, case_file, output) : run_coupled<3>(c, case_file, output);
}

}  // namespace valvefsi::fluid::app
