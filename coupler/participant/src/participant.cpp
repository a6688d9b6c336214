#include "valvefsi/coupling/participant.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#include "valvefsi/coupling/envelope_codec.hpp"
#include "valvefsi/coupling/protocol_version.hpp"
#include "valvefsi/coupling/wire_arrays.hpp"

namespace valvefsi::coupling {

namespace {

constexpr const char* kCoupler = "coupler";
// Goodbyes (Finish, Abort) get this long to leave before the socket closes.
constexpr std::chrono::milliseconds kGoodbyeLinger{500};

}  // namespace

const char* role_name(ParticipantRole role) { return role == ParticipantRole::fluid ? "fluid" : "solid"; }

Participant::Participant(ParticipantOptions options)
    : options_(std::move(options)), name_(role_name(options_.role)) {
  if (options_.solver_name.empty()) {
    throw std::invalid_argument(fmt::format("participant '{}': solver_name is empty", name_));
  }
  if (options_.endpoint.empty()) {
    throw std::invalid_argument(fmt::format("participant '{}': endpoint is empty (use resolve_endpoint())", name_));
  }
  if (options_.spatial_dimension != 2 && options_.spatial_dimension != 3) {
    throw std::invalid_argument(fmt::format("participant '{}': spatial_dimension = {}: allowed 2 or 3", name_,
                                            options_.spatial_dimension));
  }
  channel_ = MessageChannel::connect(options_.endpoint, name_, options_.liveness);
  if (options_.exit_when_coupler_lost) {
    // Between calls the solver computes; a dead coupler must not let it run on for hours.
    channel_->set_fault_handler([name = name_](const TransportError& error) {
      spdlog::error("participant '{}': {}; stopping", name, error.what());
      std::fflush(nullptr);
      std::_Exit(error.exit_code());
    });
  }
}

Participant::~Participant() {
  if (channel_) channel_->close();
}

void Participant::require_stage(Stage expected, const char* call) const {
  if (stage_ != expected) {
    throw std::logic_error(fmt::format("participant '{}': {} called out of order (see participant.hpp)", name_, call));
  }
}

void Participant::protocol_violation(const protocol::Envelope& received, const char* expected) {
  const std::string message = fmt::format("the coupler sent '{}' where participant '{}' expected {}",
                                          body_name(received), name_, expected);
  abort(message);
  throw ProtocolError(message);
}

void Participant::handshake() {
  protocol::Envelope hello;
  auto* handshake = hello.mutable_handshake();
  handshake->set_protocol_version(kProtocolVersion);
  handshake->set_role(options_.role == ParticipantRole::fluid ? protocol::ROLE_FLUID : protocol::ROLE_SOLID);
  handshake->set_solver_name(options_.solver_name);
  handshake->set_solver_version(options_.solver_version);
  handshake->set_spatial_dimension(static_cast<std::uint32_t>(options_.spatial_dimension));
  if (options_.can_checkpoint) handshake->add_capabilities("checkpoint");
  if (options_.can_restart) handshake->add_capabilities("restart");
  for (const auto& capability : options_.extra_capabilities) handshake->add_capabilities(capability);
  channel_->send(kCoupler, std::move(hello));

  const auto answer = channel_->receive_from(kCoupler);
  if (!answer.has_handshake_accepted()) protocol_violation(answer, "handshake_accepted");
  const auto& accepted = answer.handshake_accepted();
  session_.partner_solver_name = accepted.partner_solver_name();
  session_.partner_solver_version = accepted.partner_solver_version();
  session_.coupler_version = accepted.coupler_version();
  session_.scheme = accepted.scheme();
  session_.implicit = accepted.implicit();
  session_.restart_directory = accepted.restart_directory();
  session_.restart_time = accepted.restart_time();
  if (accepted.heartbeat_interval_s() > 0.0 && accepted.peer_timeout_s() > 0.0) {
    LivenessSettings liveness = options_.liveness;
    liveness.heartbeat_interval = std::chrono::duration<double>(accepted.heartbeat_interval_s());
    liveness.peer_timeout = std::chrono::duration<double>(accepted.peer_timeout_s());
    channel_->set_liveness(liveness);
  }
  spdlog::info("participant '{}' ({} {}): coupled with {} {} by coupler {}, scheme {}", name_,
               options_.solver_name, options_.solver_version, session_.partner_solver_name,
               session_.partner_solver_version, session_.coupler_version, session_.scheme);
}

void Participant::initialize_solid(const InterfaceSurfaceData& surface, const InterfaceMotion& initial_motion) {
  require_stage(Stage::connected, "initialize_solid()");
  if (options_.role != ParticipantRole::solid) {
    throw std::logic_error(fmt::format("participant '{}': initialize_solid() is for the solid", name_));
  }
  const Eigen::Index nodes = surface.positions.cols();
  const auto who = fmt::format("participant '{}'", name_);
  if (nodes == 0) throw std::invalid_argument(who + ": the interface surface has no nodes");
  if (surface.nodes_per_cell != 2 && surface.nodes_per_cell != 3) {
    throw std::invalid_argument(fmt::format("{}: nodes_per_cell = {}: allowed 2 (segments) or 3 (triangles)", who,
                                            surface.nodes_per_cell));
  }
  if (surface.cells.rows() != surface.nodes_per_cell ||
      (surface.cells.size() > 0 && (surface.cells.minCoeff() < 0 || surface.cells.maxCoeff() >= nodes))) {
    throw std::invalid_argument(fmt::format("{}: cells must be {} x n_cells with node indices in [0, {})", who,
                                            surface.nodes_per_cell, nodes));
  }
  if (surface.node_areas.size() != nodes ||
      (surface.node_thickness.size() != 0 && surface.node_thickness.size() != nodes)) {
    throw std::invalid_argument(fmt::format("{}: {} nodes need {} node areas (got {}) and 0 or {} thicknesses (got {})",
                                            who, nodes, nodes, surface.node_areas.size(), nodes,
                                            surface.node_thickness.size()));
  }
  if (initial_motion.positions.cols() != nodes || initial_motion.velocities.cols() != nodes) {
    throw std::invalid_argument(fmt::format("{}: the initial motion must have {} positions and velocities", who, nodes));
  }
  handshake();

  protocol::Envelope surface_message;
  auto* wire = surface_message.mutable_interface_surface();
  pack_points(surface.positions, wire->mutable_positions(), who, "interface_surface.positions");
  wire->set_nodes_per_cell(static_cast<std::uint32_t>(surface.nodes_per_cell));
  wire->mutable_cells()->Reserve(static_cast<int>(surface.cells.size()));
  for (Eigen::Index i = 0; i < surface.cells.size(); ++i) {
    wire->add_cells(static_cast<std::uint32_t>(surface.cells.data()[i]));
  }
  pack_scalars(surface.node_areas, wire->mutable_node_areas(), who, "interface_surface.node_areas");
  pack_scalars(surface.node_thickness, wire->mutable_node_thickness(), who, "interface_surface.node_thickness");
  channel_->send(kCoupler, std::move(surface_message));

  protocol::Envelope motion_message;
  auto* motion = motion_message.mutable_initial_motion();
  pack_points(initial_motion.positions, motion->mutable_positions(), who, "initial_motion.positions");
  pack_points(initial_motion.velocities, motion->mutable_velocities(), who, "initial_motion.velocities");
  channel_->send(kCoupler, std::move(motion_message));

  surface_ = surface;
  interface_size_ = nodes;
  stage_ = Stage::initialized;
}

void Participant::initialize_fluid(const std::function<InterfacePoints(const InterfaceSurfaceData&)>& place_markers) {
  require_stage(Stage::connected, "initialize_fluid()");
  if (options_.role != ParticipantRole::fluid) {
    throw std::logic_error(fmt::format("participant '{}': initialize_fluid() is for the fluid", name_));
  }
  handshake();
  const auto message = channel_->receive_from(kCoupler);
  if (!message.has_interface_surface()) protocol_violation(message, "interface_surface");
  const auto& wire = message.interface_surface();
  const std::string sender = "the coupler";
  surface_.positions = unpack_points(wire.positions(), -1, sender, "interface_surface.positions");
  const Eigen::Index nodes = surface_.positions.cols();
  surface_.nodes_per_cell = static_cast<int>(wire.nodes_per_cell());
  if ((surface_.nodes_per_cell != 2 && surface_.nodes_per_cell != 3) ||
      wire.cells_size() % surface_.nodes_per_cell != 0) {
    throw ProtocolError(fmt::format("the coupler sent a surface with nodes_per_cell = {} and {} cell entries",
                                    surface_.nodes_per_cell, wire.cells_size()));
  }
  surface_.cells.resize(surface_.nodes_per_cell, wire.cells_size() / surface_.nodes_per_cell);
  for (int i = 0; i < wire.cells_size(); ++i) {
    if (wire.cells(i) >= static_cast<std::uint32_t>(nodes)) {
      throw ProtocolError(fmt::format("the coupler sent interface_surface.cells[{}] = {}: allowed < {} nodes", i,
                                      wire.cells(i), nodes));
    }
    surface_.cells.data()[i] = static_cast<int>(wire.cells(i));
  }
  surface_.node_areas = unpack_scalars(wire.node_areas(), nodes, sender, "interface_surface.node_areas");
  surface_.node_thickness = wire.node_thickness_size() == 0
                                ? Eigen::VectorXd()
                                : unpack_scalars(wire.node_thickness(), nodes, sender, "interface_surface.node_thickness");

  const InterfacePoints points = place_markers(surface_);
  const auto who = fmt::format("participant '{}'", name_);
  if (points.positions.cols() == 0) throw std::invalid_argument(who + ": placed no interface points");
  if (points.areas.size() != 0 && points.areas.size() != points.positions.cols()) {
    throw std::invalid_argument(fmt::format("{}: {} interface points need 0 or {} areas (got {})", who,
                                            points.positions.cols(), points.positions.cols(), points.areas.size()));
  }
  protocol::Envelope cloud_message;
  auto* cloud = cloud_message.mutable_interface_point_cloud();
  pack_points(points.positions, cloud->mutable_positions(), who, "interface_point_cloud.positions");
  pack_scalars(points.areas, cloud->mutable_point_areas(), who, "interface_point_cloud.point_areas");
  channel_->send(kCoupler, std::move(cloud_message));
  interface_size_ = points.positions.cols();
  stage_ = Stage::initialized;
}

bool Participant::next_window(Window& window) {
  require_stage(Stage::initialized, "next_window()");
  window.save_checkpoint = false;
  window.restore_checkpoint = false;
  window.write_restart = false;
  window.restart_directory.clear();
  const std::string sender = "the coupler";
  for (;;) {
    const auto message = channel_->receive_from(kCoupler);
    switch (message.body_case()) {
      case protocol::Envelope::kCheckpointSave: window.save_checkpoint = true; break;
      case protocol::Envelope::kCheckpointRestore: window.restore_checkpoint = true; break;
      case protocol::Envelope::kRestartWrite:
        if (!options_.can_restart) protocol_violation(message, "no restart_write (it has no 'restart' capability)");
        window.write_restart = true;
        window.restart_directory = message.restart_write().directory();
        break;
      case protocol::Envelope::kConverged: {
        const auto& converged = message.converged();
        if (!converged.converged()) {
          spdlog::warn("participant '{}': window ending at t = {} s stopped after {} iterations, residual {:.3e}",
                       name_, converged.time(), converged.iterations(), converged.relative_residual());
        }
        break;
      }
      case protocol::Envelope::kFinish:
        spdlog::info("participant '{}': the coupler ended the run ({})", name_, message.finish().reason());
        stage_ = Stage::finished;
        return false;
      case protocol::Envelope::kWindowCommand: {
        const auto& command = message.window_command();
        window.time = command.window().time();
        window.size = command.window().window_size();
        window.index = command.window().window_index();
        window.iteration = command.window().iteration();
        if (options_.role == ParticipantRole::fluid) {
          if (!command.has_motion()) protocol_violation(message, "a window_command with motion");
          window.motion.positions =
              unpack_points(command.motion().positions(), interface_size_, sender, "window_command.motion.positions");
          window.motion.velocities =
              unpack_points(command.motion().velocities(), interface_size_, sender, "window_command.motion.velocities");
        } else {
          if (!command.has_loads()) protocol_violation(message, "a window_command with loads");
          window.loads.forces = unpack_points(command.loads().forces(), interface_size_, sender, "window_command.loads.forces");
        }
        stage_ = Stage::in_window;
        return true;
      }
      default: protocol_violation(message, "a window_command, checkpoint or finish");
    }
  }
}

void Participant::send_done(protocol::WindowDone done) {
  protocol::Envelope envelope;
  *envelope.mutable_window_done() = std::move(done);
  channel_->send(kCoupler, std::move(envelope));
  stage_ = Stage::initialized;
}

void Participant::complete_window(const InterfaceLoads& loads, double max_stable_window) {
  require_stage(Stage::in_window, "complete_window()");
  if (options_.role != ParticipantRole::fluid) {
    throw std::logic_error(fmt::format("participant '{}': the solid completes a window with motion, not loads", name_));
  }
  if (loads.forces.cols() != interface_size_) {
    throw std::invalid_argument(fmt::format("participant '{}': {} forces for {} interface points", name_,
                                            loads.forces.cols(), interface_size_));
  }
  protocol::WindowDone done;
  done.set_max_stable_window(max_stable_window);
  pack_points(loads.forces, done.mutable_loads()->mutable_forces(), fmt::format("participant '{}'", name_),
              "window_done.loads.forces");
  send_done(std::move(done));
}

void Participant::complete_window(const InterfaceMotion& motion, double max_stable_window) {
  require_stage(Stage::in_window, "complete_window()");
  if (options_.role != ParticipantRole::solid) {
    throw std::logic_error(fmt::format("participant '{}': the fluid completes a window with loads, not motion", name_));
  }
  if (motion.positions.cols() != interface_size_ || motion.velocities.cols() != interface_size_) {
    throw std::invalid_argument(fmt::format("participant '{}': motion with {} positions and {} velocities for {} nodes",
                                            name_, motion.positions.cols(), motion.velocities.cols(), interface_size_));
  }
  protocol::WindowDone done;
  done.set_max_stable_window(max_stable_window);
  const auto who = fmt::format("participant '{}'", name_);
  pack_points(motion.positions, done.mutable_motion()->mutable_positions(), who, "window_done.motion.positions");
  pack_points(motion.velocities, done.mutable_motion()->mutable_velocities(), who, "window_done.motion.velocities");
  send_done(std::move(done));
}

void Participant::finalize() {
  require_stage(Stage::finished, "finalize()");
  protocol::Envelope goodbye;
  goodbye.mutable_finish()->set_reason(fmt::format("participant '{}' finished", name_));
  channel_->send(kCoupler, std::move(goodbye));
  channel_->close(kGoodbyeLinger);
  stage_ = Stage::closed;
}

void Participant::abort(const std::string& reason) {
  if (stage_ == Stage::closed) return;
  stage_ = Stage::closed;
  try {
    protocol::Envelope envelope;
    auto* abort = envelope.mutable_abort();
    abort->set_reason(reason);
    abort->set_origin(options_.role == ParticipantRole::fluid ? protocol::ROLE_FLUID : protocol::ROLE_SOLID);
    abort->set_participant(name_);
    channel_->send(kCoupler, std::move(envelope));
  } catch (const TransportError&) {
    // The coupler is gone already; nobody left to tell.
  }
  channel_->close(kGoodbyeLinger);
}

}  // namespace valvefsi::coupling
