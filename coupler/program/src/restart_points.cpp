#include "valvefsi/coupler/restart_points.hpp"

#include <fmt/format.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "valvefsi/coupling/restart_file.hpp"

namespace valvefsi::coupler {

void write_coupler_restart(const std::filesystem::path& folder, const CouplerRestartState& state) {
  coupling::RestartWriter file(coupling::restart_file_path(folder, "coupler"));
  file.put("time", state.time);
  file.put_integer("windows", static_cast<std::int64_t>(state.windows));
  file.put_integer("total_iterations", state.total_iterations);
  file.put_integer("unconverged_windows", static_cast<std::int64_t>(state.unconverged_windows));
  file.put("solid_positions", state.solid_positions);
  file.put("solid_velocities", state.solid_velocities);
  file.put("previous_node_forces", state.previous_node_forces);
  file.put("motion_velocities", state.motion_velocities);
  file.put("fluid_proposal", state.fluid_proposal);
  file.put("solid_proposal", state.solid_proposal);
  file.put("acceleration_integers", std::span<const std::int64_t>(state.acceleration.integers));
  file.put_integer("acceleration_vector_count",
                   static_cast<std::int64_t>(state.acceleration.vectors.size()));
  for (std::size_t k = 0; k < state.acceleration.vectors.size(); ++k) {
    const auto& v = state.acceleration.vectors[k];
    file.put(fmt::format("acceleration_vector_{}", k),
             std::span<const double>(v.data(), static_cast<std::size_t>(v.size())));
  }
  file.commit();
}

CouplerRestartState read_coupler_restart(const std::filesystem::path& folder,
                                         Eigen::Index solid_nodes) {
  const coupling::RestartReader file(coupling::restart_file_path(folder, "coupler"));
  CouplerRestartState state;
  state.time = file.scalar("time");
  state.windows = static_cast<std::uint64_t>(file.integer("windows"));
  state.total_iterations = file.integer("total_iterations");
  state.unconverged_windows = static_cast<std::uint64_t>(file.integer("unconverged_windows"));
  state.solid_positions = file.matrix3x("solid_positions", solid_nodes);
  state.solid_velocities = file.matrix3x("solid_velocities", solid_nodes);
  state.previous_node_forces = file.matrix3x("previous_node_forces", solid_nodes);
  state.motion_velocities = file.has("motion_velocities") ? file.matrix3x("motion_velocities", solid_nodes)
                                                        : state.solid_velocities;
  state.fluid_proposal = file.scalar("fluid_proposal");
  state.solid_proposal = file.scalar("solid_proposal");
  state.acceleration.integers = file.integers("acceleration_integers");
  const auto count = file.integer("acceleration_vector_count");
  for (std::int64_t k = 0; k < count; ++k) {
    const auto values = file.doubles(fmt::format("acceleration_vector_{}", k));
    state.acceleration.vectors.emplace_back(
        Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size())));
  }
  return state;
}

double restart_folder_time(const std::filesystem::path& folder) {
  return coupling::RestartReader(coupling::restart_file_path(folder, "coupler")).scalar("time");
}

}  // namespace valvefsi::coupler
