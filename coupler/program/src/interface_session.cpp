#include "valvefsi/coupler/interface_session.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <map>
#include <stdexcept>

#include "valvefsi/coupling/envelope_codec.hpp"
#include "valvefsi/coupling/protocol_version.hpp"
#include "valvefsi/coupling/wire_arrays.hpp"

namespace valvefsi::coupler {

namespace {

using coupling::MessageChannel;
using coupling::ProtocolError;

std::string who(const std::string& peer) { return MessageChannel::describe(peer); }

protocol::Envelope expect(MessageChannel& channel, const std::string& peer, protocol::Envelope::BodyCase body,
                          const char* body_label) {
  auto message = channel.receive_from(peer);
  if (message.body_case() != body) {
    throw ProtocolError(fmt::format("{} sent '{}' where the coupler expected '{}'", who(peer),
                                    coupling::body_name(message), body_label));
  }
  return message;
}

bool has_capability(const PeerInfo& peer, const std::string& capability) {
  return std::find(peer.capabilities.begin(), peer.capabilities.end(), capability) != peer.capabilities.end();
}

std::map<std::string, PeerInfo> receive_handshakes(MessageChannel& channel) {
  std::map<std::string, PeerInfo> peers;
  while (peers.size() < 2) {
    auto incoming = channel.receive_any();
    if (incoming.peer != kFluid && incoming.peer != kSolid) {
      spdlog::warn("coupler: ignoring a '{}' message from unknown peer '{}' (participants are 'fluid' and 'solid')",
                   coupling::body_name(incoming.envelope), incoming.peer);
      continue;
    }
    if (!incoming.envelope.has_handshake() || peers.count(incoming.peer) != 0) {
      throw ProtocolError(fmt::format("{} sent '{}' where the coupler expected its handshake", who(incoming.peer),
                                      coupling::body_name(incoming.envelope)));
    }
    const auto& hello = incoming.envelope.handshake();
    const auto expected_role = incoming.peer == kFluid ? protocol::ROLE_FLUID : protocol::ROLE_SOLID;
    if (hello.role() != expected_role) {
      throw ProtocolError(fmt::format("{} announced role {} in its handshake; its connection name says {}",
                                      who(incoming.peer), protocol::Role_Name(hello.role()),
                                      protocol::Role_Name(expected_role)));
    }
    if (hello.protocol_version() != coupling::kProtocolVersion) {
      throw ProtocolError(fmt::format("protocol version mismatch: {} ({}) speaks version {}, the coupler speaks version {}",
                                      who(incoming.peer), hello.solver_name(), hello.protocol_version(),
                                      coupling::kProtocolVersion));
    }
    PeerInfo info{hello.solver_name(), hello.solver_version(),
                  {hello.capabilities().begin(), hello.capabilities().end()},
                  static_cast<int>(hello.spatial_dimension())};
    spdlog::info("coupler: {} is {} {} ({}D)", who(incoming.peer), info.solver_name, info.solver_version,
                 info.spatial_dimension);
    peers.emplace(incoming.peer, std::move(info));
  }
  return peers;
}

}  // namespace

double default_rbf_support_radius(const coupling::InterfaceMesh& surface) {
  double total = 0.0;
  long edges = 0;
  for (Eigen::Index c = 0; c < surface.cells.cols(); ++c) {
    for (int a = 0; a < surface.nodes_per_cell; ++a) {
      const int b = (a + 1) % surface.nodes_per_cell;
      if (surface.nodes_per_cell == 2 && a == 1) break;
      total += (surface.positions.col(surface.cells(a, c)) - surface.positions.col(surface.cells(b, c))).norm();
      ++edges;
    }
  }
  if (edges == 0) throw std::invalid_argument("coupling.rbf_support_radius = 0 needs a surface with cells to size it");
  return 3.0 * total / static_cast<double>(edges);
}

InterfaceSession open_session(MessageChannel& channel, const CouplerSettings& settings) {
  InterfaceSession session;
  auto peers = receive_handshakes(channel);
  session.fluid = peers.at(kFluid);
  session.solid = peers.at(kSolid);
  if (session.fluid.spatial_dimension != session.solid.spatial_dimension) {
    throw ProtocolError(fmt::format("participant 'fluid' works in {}D and participant 'solid' in {}D; both must agree",
                                    session.fluid.spatial_dimension, session.solid.spatial_dimension));
  }
  const bool implicit = settings.scheme == SchemeKind::serial_implicit;
  if (implicit) {
    for (const auto& [name, info] : {std::pair{kFluid, session.fluid}, std::pair{kSolid, session.solid}}) {
      if (!has_capability(info, "checkpoint")) {
        throw ProtocolError(fmt::format(
            "coupling.scheme = SERIAL_IMPLICIT needs checkpoints, but {} ({}) has no 'checkpoint' capability; "
            "use SERIAL_EXPLICIT or PARALLEL_EXPLICIT",
            who(name), info.solver_name));
      }
    }
  }
  const bool restarts = settings.restart_interval > 0.0 || !settings.restart_from.empty();
  if (restarts) {
    for (const auto& [name, info] : {std::pair{kFluid, session.fluid}, std::pair{kSolid, session.solid}}) {
      if (!has_capability(info, "restart")) {
        throw ProtocolError(fmt::format(
            "{} needs restart files, but {} ({}) has no 'restart' capability; set coupling.restart_interval_s = 0 "
            "and run without --restart",
            settings.restart_from.empty() ? fmt::format("coupling.restart_interval_s = {}", settings.restart_interval)
                                          : fmt::format("--restart {}", settings.restart_from.string()),
            who(name), info.solver_name));
      }
    }
  }
  for (const auto& [name, partner] : {std::pair{kFluid, session.solid}, std::pair{kSolid, session.fluid}}) {
    protocol::Envelope accepted;
    auto* body = accepted.mutable_handshake_accepted();
    body->set_protocol_version(coupling::kProtocolVersion);
    body->set_coupler_version(VALVEFSI_VERSION);
    body->set_partner_solver_name(partner.solver_name);
    body->set_partner_solver_version(partner.solver_version);
    body->set_scheme(scheme_label(settings));
    body->set_implicit(implicit);
    body->set_heartbeat_interval_s(settings.liveness.heartbeat_interval.count());
    body->set_peer_timeout_s(settings.liveness.peer_timeout.count());
    if (!settings.restart_from.empty()) {
      body->set_restart_directory(settings.restart_from.string());
      body->set_restart_time(settings.restart_time);
    }
    channel.send(name, std::move(accepted));
  }

  // The solid's surface goes to the fluid unchanged; the coupler keeps a copy for the mapping.
  auto surface_message = expect(channel, kSolid, protocol::Envelope::kInterfaceSurface, "interface_surface");
  const auto& surface = surface_message.interface_surface();
  const std::string solid_name = who(kSolid);
  session.solid_surface.positions = coupling::unpack_points(surface.positions(), -1, solid_name, "interface_surface.positions");
  const Eigen::Index nodes = session.solid_surface.positions.cols();
  session.solid_surface.nodes_per_cell = static_cast<int>(surface.nodes_per_cell());
  if ((surface.nodes_per_cell() != 2 && surface.nodes_per_cell() != 3) || surface.cells_size() % surface.nodes_per_cell() != 0) {
    throw ProtocolError(fmt::format("{} sent nodes_per_cell = {} with {} cell entries: allowed 2 or 3, dividing the entries",
                                    solid_name, surface.nodes_per_cell(), surface.cells_size()));
  }
  session.solid_surface.cells.resize(surface.nodes_per_cell(), surface.cells_size() / surface.nodes_per_cell());
  for (int i = 0; i < surface.cells_size(); ++i) {
    if (surface.cells(i) >= static_cast<std::uint32_t>(nodes)) {
      throw ProtocolError(fmt::format("{} sent interface_surface.cells[{}] = {}: allowed < {} (the node count)", solid_name,
                                      i, surface.cells(i), nodes));
    }
    session.solid_surface.cells.data()[i] = static_cast<int>(surface.cells(i));
  }
  session.solid_surface.node_areas = coupling::unpack_scalars(surface.node_areas(), nodes, solid_name, "interface_surface.node_areas");

  auto motion_message = expect(channel, kSolid, protocol::Envelope::kInitialMotion, "initial_motion");
  session.solid_initial_positions =
      coupling::unpack_points(motion_message.initial_motion().positions(), nodes, solid_name, "initial_motion.positions");
  session.solid_initial_velocities =
      coupling::unpack_points(motion_message.initial_motion().velocities(), nodes, solid_name, "initial_motion.velocities");

  protocol::Envelope forward;
  *forward.mutable_interface_surface() = surface;
  channel.send(kFluid, std::move(forward));

  auto cloud_message = expect(channel, kFluid, protocol::Envelope::kInterfacePointCloud, "interface_point_cloud");
  session.fluid_reference =
      coupling::unpack_points(cloud_message.interface_point_cloud().positions(), -1, who(kFluid), "interface_point_cloud.positions");
  if (session.fluid_reference.cols() == 0) throw ProtocolError("participant 'fluid' sent an empty interface point cloud");

  auto mapping_options = settings.mapping;
  if (mapping_options.method == coupling::MappingMethod::radial_basis && mapping_options.rbf_support_radius <= 0.0) {
    mapping_options.rbf_support_radius = default_rbf_support_radius(session.solid_surface);
  }
  session.mapping = std::make_unique<coupling::InterfaceMapping>(
      coupling::InterfaceMapping::build(session.solid_surface, session.fluid_reference, mapping_options));
  spdlog::info("coupler: interface of {} solid nodes and {} fluid points mapped", nodes, session.fluid_reference.cols());
  return session;
}

}  // namespace valvefsi::coupler
