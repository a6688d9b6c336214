#pragma once
// The start of a coupled run, as the coupler sees it: both participants' handshakes (checked:
// roles, dimension, checkpoint capability for implicit schemes), the solid's surface and
// initial motion, the fluid's points, and the mapping between them.

#include <Eigen/Core>

#include <memory>
#include <string>
#include <vector>

#include "valvefsi/coupler/coupler_settings.hpp"
#include "valvefsi/coupling/interface_mapping.hpp"
#include "valvefsi/coupling/message_channel.hpp"

namespace valvefsi::coupler {

inline constexpr const char* kFluid = "fluid";
inline constexpr const char* kSolid = "solid";

struct PeerInfo {
  std::string solver_name;
  std::string solver_version;
  std::vector<std::string> capabilities;
  int spatial_dimension = 3;
};

struct InterfaceSession {
  PeerInfo fluid;
  PeerInfo solid;
  coupling::InterfaceMesh solid_surface;      // reference configuration of the solid's nodes
  Eigen::Matrix3Xd solid_initial_positions;   // at t = 0
  Eigen::Matrix3Xd solid_initial_velocities;
  Eigen::Matrix3Xd fluid_reference;           // the fluid's points as placed at the handshake
  std::unique_ptr<coupling::InterfaceMapping> mapping;  // fluid points <- solid nodes
};

// Runs the start-up exchange on a bound channel (peers "fluid" and "solid" expected).
// Throws PeerLost/ProtocolError/RunAborted, std::invalid_argument when the interfaces cannot
// be mapped.
InterfaceSession open_session(coupling::MessageChannel& channel, const CouplerSettings& settings);

// RBF support radius when the case leaves it 0: three times the mean cell edge length.
double default_rbf_support_radius(const coupling::InterfaceMesh& surface);

}  // namespace valvefsi::coupler
