#pragma once
// One coupling window's traffic, in the coupler: motion to the fluid (mapped from the solid's
// nodes), loads back, loads to the solid (mapped conservatively), motion back, checkpoint and
// convergence messages. The schemes (coupling_schemes.hpp) order these calls.
//
// Motion mapping: the solid's DISPLACEMENTS (current minus reference positions) and velocities
// are mapped consistently, then added to the fluid points' reference positions, so points stay
// on the surface wherever the mapping is exact for linear fields. Loads: f_nodes = H^T f_points.

#include <Eigen/Core>

#include <filesystem>

#include "valvefsi/coupler/interface_session.hpp"
#include "valvefsi/coupling/message_channel.hpp"

namespace valvefsi::coupler {

struct WindowSpan {
  double time = 0.0;
  double size = 0.0;
  std::uint64_t index = 0;
  std::uint32_t iteration = 0;
};

struct SolidState {
  Eigen::Matrix3Xd positions;   // at the solid's nodes
  Eigen::Matrix3Xd velocities;
};

struct FluidReply {
  Eigen::Matrix3Xd forces;          // at the fluid's points (window average)
  double max_stable_window = 0.0;   // s, 0 = no preference
};

struct SolidReply {
  SolidState state;                 // at the end of the window
  double max_stable_window = 0.0;
};

class WindowExchange {
 public:
  WindowExchange(coupling::MessageChannel& channel, const InterfaceSession& session);

  // Markers start the window at the mapped `start` positions and move with the mapped
  // `velocities` (nodes) through it. Returns the fluid-side velocities sent (for the power).
  Eigen::Matrix3Xd send_motion_to_fluid(const WindowSpan& window, const Eigen::Matrix3Xd& start_positions,
                                        const Eigen::Matrix3Xd& velocities);
  FluidReply receive_fluid();
  void send_loads_to_solid(const WindowSpan& window, const Eigen::Matrix3Xd& node_forces);
  SolidReply receive_solid();

  // f_nodes = H^T f_points
  [[nodiscard]] Eigen::Matrix3Xd loads_to_nodes(const Eigen::Matrix3Xd& point_forces) const;
  void send_checkpoint_save(double time);
  void send_checkpoint_restore(double time);
  // Both participants write their state at `time` into `folder` before this window.
  void send_restart_write(double time, const std::filesystem::path& folder);
  void send_converged(double time, std::uint32_t iterations, double residual, bool converged);

  [[nodiscard]] const InterfaceSession& session() const { return session_; }

 private:
  void send_both(const protocol::Envelope& envelope);

  coupling::MessageChannel& channel_;
  const InterfaceSession& session_;
};

}  // namespace valvefsi::coupler
