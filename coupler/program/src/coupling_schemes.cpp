#include "valvefsi/coupler/coupling_schemes.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "valvefsi/coupler/oscillation_watch.hpp"
#include "valvefsi/coupler/restart_points.hpp"
#include "valvefsi/coupler/runaway_diagnosis.hpp"
#include "valvefsi/coupling/acceleration.hpp"
#include "valvefsi/coupling/restart_points.hpp"
#include "valvefsi/coupling/transport_errors.hpp"

namespace valvefsi::coupler {

namespace {

// Leftovers shorter than this fraction of a window are absorbed into the window before them.
constexpr double kSliver = 1e-6;

double power(const Eigen::Matrix3Xd& forces, const Eigen::Matrix3Xd& velocities) {
  return (forces.array() * velocities.array()).sum();
}

// The loads' work on the solid over a window: they are held over it, so F . (x_end - x_start).
double load_work(const Eigen::Matrix3Xd& node_forces, const SolidState& start, const SolidState& end) {
  return (node_forces.array() * (end.positions - start.positions).array()).sum();
}

void fill_record(WindowRecord& record, const WindowSpan& window, const Eigen::Matrix3Xd& fluid_forces,
                 const Eigen::Matrix3Xd& fluid_velocities, const Eigen::Matrix3Xd& node_forces,
                 const Eigen::Matrix3Xd& node_velocities) {
  record.time_end = window.time + window.size;
  record.size = window.size;
  record.index = window.index;
  record.force_fluid = fluid_forces.rowwise().sum();
  record.force_solid = node_forces.rowwise().sum();
  record.power_fluid = power(fluid_forces, fluid_velocities);
  record.power_solid = power(node_forces, node_velocities);
}

Eigen::VectorXd flatten(const Eigen::Matrix3Xd& m) { return Eigen::Map<const Eigen::VectorXd>(m.data(), m.size()); }
Eigen::Matrix3Xd unflatten(const Eigen::VectorXd& v) { return Eigen::Map<const Eigen::Matrix3Xd>(v.data(), 3, v.size() / 3); }

struct Proposals {
  double fluid = 0.0;
  double solid = 0.0;
};

// The velocity the fluid's points move with through the next explicit window: the solid's at
// the window's end, or its mean over the window (coupling.explicit_motion_velocity).
Eigen::Matrix3Xd next_motion_velocities(const CouplerSettings& settings, const WindowSpan& window,
                                        const SolidState& start, const SolidState& end) {
  if (!settings.explicit_motion_previous_window_mean) return end.velocities;
  return (end.positions - start.positions) / window.size;
}

WindowRecord serial_explicit_window(WindowExchange& exchange, const CouplerSettings& settings,
                                    const WindowSpan& window, SolidState& solid, Eigen::Matrix3Xd& motion_velocities,
                                    Proposals& proposals) {
  const auto fluid_velocities = exchange.send_motion_to_fluid(window, solid.positions, motion_velocities);
  const auto fluid = exchange.receive_fluid();
  const Eigen::Matrix3Xd node_forces = exchange.loads_to_nodes(fluid.forces);
  exchange.send_loads_to_solid(window, node_forces);
  auto reply = exchange.receive_solid();
  WindowRecord record;
  fill_record(record, window, fluid.forces, fluid_velocities, node_forces, motion_velocities);
  motion_velocities = next_motion_velocities(settings, window, solid, reply.state);
  record.load_work_solid = load_work(node_forces, solid, reply.state);
  solid = std::move(reply.state);
  proposals = {fluid.max_stable_window, reply.max_stable_window};
  return record;
}

WindowRecord parallel_explicit_window(WindowExchange& exchange, const CouplerSettings& settings,
                                      const WindowSpan& window, SolidState& solid, Eigen::Matrix3Xd& motion_velocities,
                                      Eigen::Matrix3Xd& previous_node_forces, Proposals& proposals) {
  const auto fluid_velocities = exchange.send_motion_to_fluid(window, solid.positions, motion_velocities);
  exchange.send_loads_to_solid(window, previous_node_forces);
  const auto fluid = exchange.receive_fluid();
  auto reply = exchange.receive_solid();
  WindowRecord record;
  fill_record(record, window, fluid.forces, fluid_velocities, previous_node_forces, motion_velocities);
  motion_velocities = next_motion_velocities(settings, window, solid, reply.state);
  record.load_work_solid = load_work(previous_node_forces, solid, reply.state);
  previous_node_forces = exchange.loads_to_nodes(fluid.forces);
  solid = std::move(reply.state);
  proposals = {fluid.max_stable_window, reply.max_stable_window};
  return record;
}

WindowRecord serial_implicit_window(WindowExchange& exchange, const CouplerSettings& settings, WindowSpan window,
                                    SolidState& solid, coupling::Acceleration& acceleration, Proposals& proposals) {
  const Eigen::Matrix3Xd& reference = exchange.session().solid_surface.positions;
  // The iterate is the solid's end-of-window displacement; start from constant velocity.
  Eigen::VectorXd input = flatten(solid.positions + window.size * solid.velocities - reference);
  acceleration.begin_window();
  exchange.send_checkpoint_save(window.time);
  WindowRecord record;
  for (int k = 0;; ++k) {
    window.iteration = static_cast<std::uint32_t>(k);
    if (k > 0) exchange.send_checkpoint_restore(window.time);
    const Eigen::Matrix3Xd end_positions = reference + unflatten(input);
    const Eigen::Matrix3Xd mean_velocities = (end_positions - solid.positions) / window.size;
    const auto fluid_velocities = exchange.send_motion_to_fluid(window, solid.positions, mean_velocities);
    const auto fluid = exchange.receive_fluid();
    const Eigen::Matrix3Xd node_forces = exchange.loads_to_nodes(fluid.forces);
    exchange.send_loads_to_solid(window, node_forces);
    auto reply = exchange.receive_solid();
    const Eigen::VectorXd output = flatten(reply.state.positions - reference);
    const double residual = coupling::relative_residual(input, output);
    fill_record(record, window, fluid.forces, fluid_velocities, node_forces, mean_velocities);
    record.iterations = k + 1;
    record.relative_residual = residual;
    if (k == 0) record.first_residual = record.smallest_residual = residual;
    record.smallest_residual = std::min(record.smallest_residual, residual);
    if (!std::isfinite(residual)) {
      throw coupling::CouplingFailed(fmt::format(
          "implicit window {} (t = {} s) diverged: the relative residual of iteration {} is not finite; try a "
          "smaller coupling.window_size or relaxation_factor",
          window.index, window.time, k + 1));
    }
    proposals = {fluid.max_stable_window, reply.max_stable_window};
    // Relative to the displacement, or absolute for a solid (nearly) at rest.
    const double rms_change = (output - input).norm() / std::sqrt(static_cast<double>(std::max<Eigen::Index>(output.size() / 3, 1)));
    record.converged = residual < settings.relative_tolerance || rms_change < settings.absolute_tolerance;
    spdlog::debug("coupler: window {} iteration {}: relative residual {:.6e}, RMS change {:.6e} m, |x| {:.6e} m, "
                  "|fluid loads| {:.17g} N, |solid output| {:.17g} m",
                  window.index, k + 1, residual, rms_change, input.norm(), fluid.forces.norm(), output.norm());
    if (record.converged || k + 1 >= settings.max_iterations) {
      acceleration.end_window();
      exchange.send_converged(window.time + window.size, static_cast<std::uint32_t>(k + 1), residual, record.converged);
      if (!record.converged) {
        spdlog::warn("coupler: window {} (t = {} s) not converged after {} iterations: relative residual {:.3e} >= {:.1e}",
                     window.index, window.time, k + 1, residual, settings.relative_tolerance);
      }
      record.load_work_solid = load_work(node_forces, solid, reply.state);
      solid = std::move(reply.state);
      return record;
    }
    input = acceleration.next_input(input, output);
  }
}

// The failure checks of a completed window (docs/coupling.md, "When the coupling fails").
void check_window(const WindowRecord& record, const WindowSpan& window, const SolidState& solid,
                  const CouplerSettings& settings, const OscillationWatch& watch, const InterfaceHistory& history) {
  // What the coupler can tell of the cause: the node's time scale and the loads' work.
  auto cause = [&](Eigen::Index node) { return explain_runaway(diagnose_runaway(history, node), settings.scheme); };
  if (!record.converged && settings.divergence_residual > 0.0 && record.relative_residual >= settings.divergence_residual) {
    throw coupling::CouplingFailed(fmt::format(
        "implicit window {} (t = {} s, size {:.3g} s) diverged: relative residual {:.3e} after {} iterations (first "
        "{:.3e}, smallest {:.3e}) >= coupling.divergence_residual = {}; try a smaller coupling.window_size, a smaller "
        "relaxation_factor, fewer iqn_reused_windows or acceleration AITKEN, and check that both solvers restore "
        "their checkpoints exactly",
        window.index, window.time, window.size, record.relative_residual, record.iterations, record.first_residual,
        record.smallest_residual, settings.divergence_residual));
  }
  if (settings.max_interface_speed > 0.0 && solid.velocities.cols() > 0) {
    Eigen::Index node = 0;
    const double speed = std::sqrt(solid.velocities.colwise().squaredNorm().maxCoeff(&node));
    if (!(speed <= settings.max_interface_speed)) {
      const Eigen::Vector3d where = 1e3 * solid.positions.col(node);
      throw coupling::CouplingFailed(fmt::format(
          "window {} (t = {} s to {} s): solid interface node {} at ({:.3f}, {:.3f}, {:.3f}) mm moves at {:.3g} m/s > "
          "coupling.max_interface_speed = {} m/s: the interface is running away. {}; raise max_interface_speed only "
          "if such speeds are physical",
          window.index, window.time, window.time + window.size, node, where.x(), where.y(), where.z(), speed,
          settings.max_interface_speed, cause(node)));
    }
  }
  if (const auto& alarm = watch.alarm()) {
    const Eigen::Vector3d where = 1e3 * solid.positions.col(alarm->node);
    const double speed = solid.velocities.col(alarm->node).norm();
    // The two rules differ only in what the blocks did and which fields to raise.
    const std::string rule =
        alarm->standing
            ? fmt::format("every one of the last {} blocks of {} windows stood at or above "
                          "coupling.runaway_standing_speed = {} m/s ({:.3g} m/s {} blocks ago): the interface "
                          "oscillates at the window's scale and does not settle",
                          alarm->blocks, alarm->block_windows, settings.runaway_standing_speed,
                          alarm->oscillation_before, alarm->blocks)
            : fmt::format("grown in each of the last {} blocks of {} windows from {:.3g} m/s, >= "
                          "coupling.runaway_oscillation_speed = {} m/s: the interface is running away (slowly)",
                          alarm->blocks, alarm->block_windows, alarm->oscillation_before,
                          settings.runaway_oscillation_speed);
    throw coupling::CouplingFailed(fmt::format(
        "window {} (t = {} s to {} s): solid interface node {} at ({:.3f}, {:.3f}, {:.3f}) mm (now at {:.3g} m/s) jumps "
        "in velocity from window to window by {:.3g} m/s RMS over the last {} windows, {}. {}; raise {} only if the "
        "leaflet really moves on the window's time scale",
        window.index, window.time, window.time + window.size, alarm->node, where.x(), where.y(), where.z(), speed,
        alarm->oscillation, alarm->block_windows, rule, cause(alarm->node),
        alarm->standing ? "runaway_standing_speed or runaway_standing_blocks"
                        : "runaway_oscillation_speed or runaway_growing_blocks"));
  }
}

}  // namespace

double next_window_size(double time, double end_time, double case_window, double fluid_proposal,
                        double solid_proposal) {
  double size = case_window;
  if (fluid_proposal > 0.0) size = std::min(size, fluid_proposal);
  if (solid_proposal > 0.0) size = std::min(size, solid_proposal);
  const double remaining = end_time - time;
  if (remaining <= size * (1.0 + kSliver)) return remaining;
  return size;
}

SchemeSummary run_coupling_scheme(WindowExchange& exchange, const CouplerSettings& settings,
                                  const WindowObserver& observe) {
  const auto& session = exchange.session();
  SolidState solid{session.solid_initial_positions, session.solid_initial_velocities};
  Eigen::Matrix3Xd previous_node_forces = Eigen::Matrix3Xd::Zero(3, session.solid_surface.positions.cols());
  // Explicit schemes: the velocity the fluid's points move with in the next window (window 0: the
  // solid's initial velocity under either choice of coupling.explicit_motion_velocity).
  Eigen::Matrix3Xd motion_velocities = solid.velocities;
  std::unique_ptr<coupling::Acceleration> acceleration;
  if (settings.scheme == SchemeKind::serial_implicit) acceleration = coupling::make_acceleration(settings.acceleration);

  // A restart starts it afresh: it needs two windows of velocities and then whole blocks.
  OscillationWatch watch(settings.runaway_oscillation_speed, settings.runaway_growing_blocks,
                         settings.runaway_standing_speed, settings.runaway_standing_blocks);
  InterfaceHistory history;
  SchemeSummary summary;
  Proposals proposals;
  double time = 0.0;
  if (!settings.restart_from.empty()) {
    const auto state = read_coupler_restart(settings.restart_from, session.solid_surface.positions.cols());
    time = state.time;
    summary.windows = state.windows;
    summary.total_iterations = state.total_iterations;
    summary.unconverged_windows = state.unconverged_windows;
    solid = {state.solid_positions, state.solid_velocities};
    previous_node_forces = state.previous_node_forces;
    motion_velocities = state.motion_velocities;
    proposals = {state.fluid_proposal, state.solid_proposal};
    if (acceleration) acceleration->restore_carried_state(state.acceleration);
    spdlog::info("coupler: continuing from {} at t = {} s (window {})", settings.restart_from.string(), time, summary.windows);
  }
  const double end_tolerance = kSliver * settings.window_size;
  // Restart points: the first window start at or after each multiple of the interval.
  auto next_restart_after = [&](double t) {
    return (std::floor(t / settings.restart_interval * (1.0 + 1e-12)) + 1.0) * settings.restart_interval;
  };
  double next_restart = settings.restart_interval > 0.0 ? next_restart_after(time) : 0.0;
  while (settings.end_time - time > end_tolerance) {
    WindowSpan window;
    window.time = time;
    window.size = next_window_size(time, settings.end_time, settings.window_size, proposals.fluid, proposals.solid);
    window.index = summary.windows;
    std::filesystem::path restart;
    if (settings.restart_interval > 0.0 && time >= next_restart * (1.0 - 1e-12)) {
      restart = coupling::restart_folder(settings.output_dir, time);
      CouplerRestartState state{time, summary.windows, summary.total_iterations, summary.unconverged_windows,
                                solid.positions, solid.velocities, previous_node_forces, motion_velocities,
                                proposals.fluid, proposals.solid,
                                acceleration ? acceleration->carried_state() : coupling::CarriedState{}};
      write_coupler_restart(restart, state);
      exchange.send_restart_write(time, restart);
      next_restart = next_restart_after(time);
    }
    WindowRecord record;
    switch (settings.scheme) {
      case SchemeKind::serial_explicit:
        record = serial_explicit_window(exchange, settings, window, solid, motion_velocities, proposals);
        break;
      case SchemeKind::parallel_explicit:
        record = parallel_explicit_window(exchange, settings, window, solid, motion_velocities, previous_node_forces,
                                          proposals);
        break;
      case SchemeKind::serial_implicit:
        record = serial_implicit_window(exchange, settings, window, solid, *acceleration, proposals);
        break;
    }
    // Both participants answered this window, so both wrote their restart files before it.
    if (!restart.empty()) {
      coupling::mark_restart_complete(restart, settings.restart_keep);
      spdlog::info("coupler: restart data at t = {} s in {}", window.time, restart.string());
    }
    record.interface_oscillation = watch.update(solid.velocities);
    history.update(solid.velocities, record.load_work_solid, record.power_solid * record.size);
    observe(record);
    check_window(record, window, solid, settings, watch, history);
    ++summary.windows;
    summary.total_iterations += record.iterations;
    if (!record.converged) ++summary.unconverged_windows;
    time = window.time + window.size;
  }
  summary.final_time = time;
  return summary;
}

}  // namespace valvefsi::coupler
