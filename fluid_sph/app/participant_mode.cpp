#include "participant_mode.hpp"

#include <omp.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "run_output.hpp"
#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/coupling/endpoint.hpp"
#include "valvefsi/coupling/participant.hpp"
#include "valvefsi/fluid/case_setup.hpp"
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
  try {
    auto setup = fluid_setup_from_case<D>(c, case_file);
    const ProbeSet<D> probes = setup.probes;
    const std::size_t plate_count = setup.plates.size();
    FluidSolver<D> solver = make_solver<D>(std::move(setup));
    solver.compute_body_forces_every_step(probes.wall_forces);
    participant = std::make_unique<coupling::Participant>(options);

    std::size_t node_count = 0;
    participant->initialize_fluid([&](const coupling::InterfaceSurfaceData& surface) {
      solver.set_immersed_surface(surface_model<D>(surface, solver.settings(), c, case_file));
      node_count = static_cast<std::size_t>(surface.positions.cols());
      coupling::InterfacePoints points;
      points.positions = surface.positions;  // the fluid's loads are at the surface nodes
      points.areas = surface.node_areas;
      return points;
    });
    const auto& p = solver.particles();
    spdlog::info("fluid_sph: coupled ({}D) with {} {}, scheme {}: {} fluid + {} wall particles, {} interface nodes, "
                 "dp = {} m, c0 = {} m/s, {} plate(s), {} OpenMP thread(s)",
                 D, participant->session().partner_solver_name, participant->session().partner_solver_version,
                 participant->session().scheme, p.count(Kind::fluid), p.count(Kind::wall), node_count,
                 solver.settings().particle_spacing, solver.settings().sound_speed, plate_count, omp_get_max_threads());

    RunOutput<D> run_output(probes, plate_count, true, output, c.run().end_time(), c.run().snapshot_interval(),
                            c.run().series_interval());
    auto& model = *solver.immersed_surface();
    std::vector<Vec<D>> end_positions(node_count), end_velocities(node_count);
    Vec<D> last_total{};
    coupling::InterfaceLoads loads{Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(node_count))};
    coupling::Window window;
    std::uint64_t repeats = 0;
    const long first_step = solver.step_count();
    bool unwritten = true;  // the initial state
    while (participant->next_window(window)) {
      if (window.restore_checkpoint) {
        solver.restore_checkpoint();
        ++repeats;
      } else if (unwritten) {
        run_output.write_due(solver, last_total);  // the state the last window ended in is accepted
      }
      if (window.save_checkpoint) solver.save_checkpoint();
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
      model.set_window_target(window.end(), end_positions, end_velocities);
      solver.reset_surface_force_average();
      solver.advance_to(window.end());
      const std::vector<Vec<D>> forces = solver.surface_force_average();
      last_total = Vec<D>{};
      for (std::size_t j = 0; j < node_count; ++j)
        for (int d = 0; d < D; ++d) {
          loads.forces(d, static_cast<Eigen::Index>(j)) = forces[j][d];
          last_total[d] += forces[j][d];
        }
      participant->complete_window(loads, 0.0);  // the fluid sub-cycles: any window suits it
      unwritten = true;
    }
    run_output.write_due(solver, last_total);
    run_output.flush();
    const ImmersedSurfaceCounters counters = model.counters();
    const double wall = run_output.elapsed();
    const double updates = static_cast<double>(p.size()) * static_cast<double>(solver.step_count() - first_step);
    spdlog::info("fluid_sph: done, t = {} s in {} steps, {} repeated windows, wall time {:.1f} s ({:.3g} particle updates/s), "
                 "{} particle(s) lost ({} by density), interface: {} put back, {} leaks, {} shifts refused; output in {}",
                 solver.time(), solver.step_count(), repeats, wall, updates / std::max(wall, 1e-9), solver.lost_count(),
                 solver.density_out_of_range_count(), counters.corrections, counters.leaks, counters.rejected_shifts,
                 output.string());
    participant->finalize();
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
