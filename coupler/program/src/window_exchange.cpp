#include "valvefsi/coupler/window_exchange.hpp"

#include <fmt/format.h>

#include "valvefsi/coupling/envelope_codec.hpp"
#include "valvefsi/coupling/wire_arrays.hpp"

namespace valvefsi::coupler {

namespace {

void fill_window(protocol::WindowBegin* begin, const WindowSpan& window) {
  begin->set_time(window.time);
  begin->set_window_size(window.size);
  begin->set_window_index(window.index);
  begin->set_iteration(window.iteration);
}

protocol::WindowDone expect_done(coupling::MessageChannel& channel, const char* peer) {
  auto message = channel.receive_from(peer);
  if (!message.has_window_done()) {
    throw coupling::ProtocolError(fmt::format("{} sent '{}' where the coupler expected 'window_done'",
                                              coupling::MessageChannel::describe(peer), coupling::body_name(message)));
  }
  return std::move(*message.mutable_window_done());
}

}  // namespace

WindowExchange::WindowExchange(coupling::MessageChannel& channel, const InterfaceSession& session)
    : channel_(channel), session_(session) {}

Eigen::Matrix3Xd WindowExchange::send_motion_to_fluid(const WindowSpan& window, const Eigen::Matrix3Xd& start_positions,
                                                      const Eigen::Matrix3Xd& velocities) {
  const Eigen::Matrix3Xd displacement = start_positions - session_.solid_surface.positions;
  const Eigen::Matrix3Xd point_positions = session_.fluid_reference + session_.mapping->map_consistent(displacement);
  Eigen::Matrix3Xd point_velocities = session_.mapping->map_consistent(velocities);
  protocol::Envelope envelope;
  auto* command = envelope.mutable_window_command();
  fill_window(command->mutable_window(), window);
  coupling::pack_points(point_positions, command->mutable_motion()->mutable_positions(), "the coupler",
                        "window_command.motion.positions");
  coupling::pack_points(point_velocities, command->mutable_motion()->mutable_velocities(), "the coupler",
                        "window_command.motion.velocities");
  channel_.send(kFluid, std::move(envelope));
  return point_velocities;
}

FluidReply WindowExchange::receive_fluid() {
  const auto done = expect_done(channel_, kFluid);
  if (!done.has_loads()) {
    throw coupling::ProtocolError("participant 'fluid' completed a window with motion; the fluid returns loads");
  }
  return FluidReply{coupling::unpack_points(done.loads().forces(), session_.fluid_reference.cols(),
                                            "participant 'fluid'", "window_done.loads.forces"),
                    done.max_stable_window()};
}

Eigen::Matrix3Xd WindowExchange::loads_to_nodes(const Eigen::Matrix3Xd& point_forces) const {
  return session_.mapping->map_conservative(point_forces);
}

void WindowExchange::send_loads_to_solid(const WindowSpan& window, const Eigen::Matrix3Xd& node_forces) {
  protocol::Envelope envelope;
  auto* command = envelope.mutable_window_command();
  fill_window(command->mutable_window(), window);
  coupling::pack_points(node_forces, command->mutable_loads()->mutable_forces(), "the coupler",
                        "window_command.loads.forces");
  channel_.send(kSolid, std::move(envelope));
}

SolidReply WindowExchange::receive_solid() {
  const auto done = expect_done(channel_, kSolid);
  if (!done.has_motion()) {
    throw coupling::ProtocolError("participant 'solid' completed a window with loads; the solid returns motion");
  }
  const auto nodes = session_.solid_surface.positions.cols();
  SolidReply reply;
  reply.state.positions = coupling::unpack_points(done.motion().positions(), nodes, "participant 'solid'",
                                                  "window_done.motion.positions");
  reply.state.velocities = coupling::unpack_points(done.motion().velocities(), nodes, "participant 'solid'",
                                                   "window_done.motion.velocities");
  reply.max_stable_window = done.max_stable_window();
  return reply;
}

void WindowExchange::send_both(const protocol::Envelope& envelope) {
  channel_.send(kFluid, envelope);
  channel_.send(kSolid, envelope);
}

void WindowExchange::send_checkpoint_save(double time) {
  protocol::Envelope envelope;
  envelope.mutable_checkpoint_save()->set_time(time);
  send_both(envelope);
}

void WindowExchange::send_restart_write(double time, const std::filesystem::path& folder) {
  protocol::Envelope envelope;
  envelope.mutable_restart_write()->set_time(time);
  envelope.mutable_restart_write()->set_directory(folder.string());
  send_both(envelope);
}

void WindowExchange::send_checkpoint_restore(double time) {
  protocol::Envelope envelope;
  envelope.mutable_checkpoint_restore()->set_time(time);
  send_both(envelope);
}

void WindowExchange::send_converged(double time, std::uint32_t iterations, double residual, bool converged) {
  protocol::Envelope envelope;
  auto* body = envelope.mutable_converged();
  body->set_time(time);
  body->set_iterations(iterations);
  body->set_relative_residual(residual);
  body->set_converged(converged);
  send_both(envelope);
}

}  // namespace valvefsi::coupler
