#pragma once
// The coupler's restart state (docs/coupling.md, "Restarts"); the folder layout is in
// valvefsi/coupling/restart_points.hpp. At the start of the first
// window at or after each multiple of coupling.restart_interval_s the coupler writes its own
// state into output/restart/t_<time>/coupler.restart.h5 and asks both participants to write
// theirs beside it; once that window is completed by both, the folder gets a COMPLETE mark,
// output/restart/LATEST names it, and older complete folders beyond restart_keep go.
#include <Eigen/Core>

#include <cstdint>
#include <filesystem>

#include "valvefsi/coupling/acceleration.hpp"

namespace valvefsi::coupler {

// Everything the coupling schemes carry from one window to the next.
struct CouplerRestartState {
  double time = 0.0;          // start of the next window (s)
  std::uint64_t windows = 0;  // windows completed
  std::int64_t total_iterations = 0;
  std::uint64_t unconverged_windows = 0;
  Eigen::Matrix3Xd solid_positions;  // the solid's nodes at `time`
  Eigen::Matrix3Xd solid_velocities;
  Eigen::Matrix3Xd previous_node_forces;  // parallel explicit: the loads the solid gets next
  // explicit: the velocity the fluid's points move with next (the solid's velocity, or its
  // previous window's mean with coupling.explicit_motion_velocity); older files: solid_velocities
  Eigen::Matrix3Xd motion_velocities;
  double fluid_proposal = 0.0;            // window sizes proposed for the next window (s)
  double solid_proposal = 0.0;
  coupling::CarriedState acceleration;
};

void write_coupler_restart(const std::filesystem::path& folder, const CouplerRestartState& state);
// Throws std::runtime_error naming the file and entry, or when the solid's node count differs.
CouplerRestartState read_coupler_restart(const std::filesystem::path& folder,
                                         Eigen::Index solid_nodes);
// The coupler's state time in a restart folder.
double restart_folder_time(const std::filesystem::path& folder);

}  // namespace valvefsi::coupler
