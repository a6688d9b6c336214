#pragma once
// The API a solver links to take part in a coupled run (library valvefsi_participant).
//
// Order of calls (docs/writing-a-participant.md has a complete example):
//
//   Participant p(options);                       // connects; nothing sent yet
//   p.initialize_solid(surface, initial_motion);  // solid   -- or --
//   p.initialize_fluid(place_markers);            // fluid: gets the surface, returns its points
//   Window w;
//   while (p.next_window(w)) {                    // blocks until the coupler opens a window
//     if (w.restore_checkpoint) restore();        // implicit scheme: repeat this window
//     if (w.save_checkpoint) save();              // implicit scheme: first pass of a window
//     if (w.write_restart) write_restart(restart_file_path(w.restart_directory, p.name()));
//     advance(w.time, w.size, w.loads / w.motion);
//     p.complete_window(my_output, my_stable_step);
//   }
//   p.finalize();                                 // after writing output; or p.abort(reason)
//
// Restarts (options.can_restart): when session().restart_directory is not empty after the
// initialize call, load your state from restart_file_path(that folder, name()) before the
// first window (which starts at session().restart_time); valvefsi/coupling/restart_file.hpp
// reads and writes such files.
//
// Faults: every call throws a TransportError (PeerLost, ProtocolError, RunAborted) whose
// what() names who failed and why; exit with its exit_code(). While the solver computes
// between calls a background thread keeps sending heartbeats; if the coupler dies, freezes or
// aborts meanwhile, the process is stopped with a message and a non-zero exit code (unless
// options.exit_when_coupler_lost is false), so a long step never outlives its run.
// Only one process of an MPI solver (rank 0) owns a Participant; it gathers and scatters.

#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "valvefsi/coupling/message_channel.hpp"
#include "valvefsi/coupling/transport_errors.hpp"

namespace valvefsi::coupling {

enum class ParticipantRole { fluid, solid };

// "fluid" / "solid": also the participant's name on the wire and in every message.
const char* role_name(ParticipantRole role);

struct ParticipantOptions {
  ParticipantRole role = ParticipantRole::fluid;
  std::string solver_name;         // e.g. "fluid_sph"
  std::string solver_version;      // e.g. "0.1.0"
  std::string endpoint;            // resolve_endpoint(case.coupling().endpoint(), output_dir)
  int spatial_dimension = 3;       // 2 (z = 0) or 3; both participants must agree
  bool can_checkpoint = false;     // true if the solver can save/restore (implicit schemes)
  bool can_restart = false;        // true if the solver writes and reads restart files
  std::vector<std::string> extra_capabilities;
  LivenessSettings liveness;       // until the coupler's settings arrive with the handshake
  bool exit_when_coupler_lost = true;
};

// The solid's interface surface (reference configuration).
struct InterfaceSurfaceData {
  Eigen::Matrix3Xd positions;                                 // m
  int nodes_per_cell = 3;                                     // 3 triangles (3D), 2 segments (2D)
  Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic> cells;   // nodes_per_cell x n_cells, 0-based
  Eigen::VectorXd node_areas;                                 // m^2 (m in 2D)
  Eigen::VectorXd node_thickness;                             // m; may be empty
};

// The fluid's interface points (markers), in the reference configuration.
struct InterfacePoints {
  Eigen::Matrix3Xd positions;  // m
  Eigen::VectorXd areas;       // m^2 (m in 2D); may be empty
};

struct InterfaceMotion {
  Eigen::Matrix3Xd positions;   // m
  Eigen::Matrix3Xd velocities;  // m/s
};

struct InterfaceLoads {
  Eigen::Matrix3Xd forces;  // N (N/m in 2D), one per point/node
};

// One coupling window as the coupler opens it.
struct Window {
  double time = 0.0;             // start (s)
  double size = 0.0;             // length (s); advance exactly to time + size
  std::uint64_t index = 0;       // 0, 1, 2, ...
  std::uint32_t iteration = 0;   // 0 on the first pass, > 0 when the implicit scheme repeats it
  bool save_checkpoint = false;     // save your state (at `time`) before advancing
  bool restore_checkpoint = false;  // go back to the saved state before advancing
  // Write your whole state at `time` (before advancing) into
  // restart_file_path(restart_directory, participant name): a restarted run starts from it.
  bool write_restart = false;
  std::string restart_directory;
  // Input, at your points/nodes in your order:
  InterfaceMotion motion;  // fluid: markers at `time`, moving with `velocities` through the window
  InterfaceLoads loads;    // solid: nodal forces, constant over the window (window average)
  [[nodiscard]] double end() const { return time + size; }
};

// What the coupler said at the handshake.
struct SessionInfo {
  std::string partner_solver_name;
  std::string partner_solver_version;
  std::string coupler_version;
  std::string scheme;   // "serial-explicit", "parallel-explicit", "serial-implicit/iqn-ils", ...
  bool implicit = false;
  // A restarted run: load your state from this folder before the first window (empty = t = 0).
  std::string restart_directory;
  double restart_time = 0.0;
};

class Participant {
 public:
  // Pre: options.endpoint set, solver_name non-empty. Post: connected (the coupler may start
  // later; it must answer within liveness.startup_timeout), heartbeats running.
  explicit Participant(ParticipantOptions options);
  // Closes without a goodbye if neither finalize() nor abort() was called.
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  // Solid only. Pre: constructed, not initialized; `surface` consistent (cells within range,
  // one area per node), `initial_motion` at the surface nodes at t = 0, all finite.
  // Post: handshake accepted, surface and initial motion sent; next call: next_window().
  void initialize_solid(const InterfaceSurfaceData& surface, const InterfaceMotion& initial_motion);

  // Fluid only. Pre: constructed, not initialized. Performs the handshake, receives the solid's
  // surface, calls `place_markers(surface)` and sends the returned points (finite, >= 1).
  // Post: surface() holds the solid's surface; next call: next_window().
  void initialize_fluid(const std::function<InterfacePoints(const InterfaceSurfaceData&)>& place_markers);

  // Pre: initialized, and the previous window (if any) completed. Blocks until the coupler
  // opens a window (returns true, `window` filled, checkpoint flags set) or ends the run
  // (returns false; then call finalize()).
  bool next_window(Window& window);

  // Fluid: forces on its points, averaged over the window (one column per point).
  // Pre: next_window() returned true and this window is not yet completed; loads finite.
  // `max_stable_window` (s, 0 = no preference) caps the next window. Post: sent.
  void complete_window(const InterfaceLoads& loads, double max_stable_window);
  // Solid: its nodes' positions and velocities at the end of the window; same rules.
  void complete_window(const InterfaceMotion& motion, double max_stable_window);

  // Pre: next_window() returned false. Post: the coupler has been told, the link is closed.
  void finalize();
  // Any time: tells the coupler (which stops the partner) and closes. Exit non-zero after it.
  void abort(const std::string& reason);

  [[nodiscard]] const SessionInfo& session() const { return session_; }
  [[nodiscard]] const InterfaceSurfaceData& surface() const { return surface_; }
  [[nodiscard]] Eigen::Index interface_size() const { return interface_size_; }
  [[nodiscard]] ParticipantRole role() const { return options_.role; }
  [[nodiscard]] const std::string& name() const { return name_; }

 private:
  enum class Stage { connected, initialized, in_window, finished, closed };
  void handshake();
  void require_stage(Stage expected, const char* call) const;
  void send_done(protocol::WindowDone done);
  [[noreturn]] void protocol_violation(const protocol::Envelope& received, const char* expected);

  ParticipantOptions options_;
  std::string name_;
  std::unique_ptr<MessageChannel> channel_;
  Stage stage_ = Stage::connected;
  SessionInfo session_;
  InterfaceSurfaceData surface_;
  Eigen::Index interface_size_ = 0;  // points (fluid) or nodes (solid)
};

}  // namespace valvefsi::coupling
