#include "valvefsi/coupler/restart_points.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "valvefsi/coupling/restart_file.hpp"

namespace valvefsi::coupler {

namespace {

constexpr const char* kComplete = "COMPLETE";
constexpr const char* kLatest = "LATEST";
constexpr const char* kFolderPrefix = "t_";

}  // namespace

std::filesystem::path restart_folder(const std::filesystem::path& output_dir, double time) {
  return output_dir / "restart" / fmt::format("{}{:.9f}", kFolderPrefix, time);
}

void write_coupler_restart(const std::filesystem::path& folder, const CouplerRestartState& state) {
  coupling::RestartWriter file(coupling::restart_file_path(folder, "coupler"));
  file.put("time", state.time);
  file.put_integer("windows", static_cast<std::int64_t>(state.windows));
  file.put_integer("total_iterations", state.total_iterations);
  file.put_integer("unconverged_windows", static_cast<std::int64_t>(state.unconverged_windows));
  file.put("solid_positions", state.solid_positions);
  file.put("solid_velocities", state.solid_velocities);
  file.put("previous_node_forces", state.previous_node_forces);
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

std::filesystem::path resolve_restart_folder(const std::filesystem::path& given) {
  if (!std::filesystem::is_directory(given))
    throw std::runtime_error(fmt::format("--restart {}: no such folder", given.string()));
  std::filesystem::path folder = given;
  if (!std::filesystem::exists(given / kComplete)) {
    std::ifstream latest(given / kLatest);
    std::string name;
    if (!(latest >> name)) {
      throw std::runtime_error(
          fmt::format("--restart {}: neither a complete restart folder (no {} mark) nor a run's "
                      "restart/ folder (no {} file)",
                      given.string(), kComplete, kLatest));
    }
    folder = given / name;
    if (!std::filesystem::exists(folder / kComplete))
      throw std::runtime_error(fmt::format("--restart {}: {} names {}, which is not complete",
                                           given.string(), kLatest, folder.string()));
  }
  for (const char* who : {"coupler", "fluid", "solid"}) {
    if (!std::filesystem::exists(coupling::restart_file_path(folder, who)))
      throw std::runtime_error(fmt::format("--restart {}: {} is missing", given.string(),
                                           coupling::restart_file_path(folder, who).string()));
  }
  return folder;
}

double restart_folder_time(const std::filesystem::path& folder) {
  return coupling::RestartReader(coupling::restart_file_path(folder, "coupler")).scalar("time");
}

void mark_restart_complete(const std::filesystem::path& folder, int keep) {
  std::ofstream(folder / kComplete) << "complete\n";
  const auto parent = folder.parent_path();
  {
    const auto temporary = parent / (std::string(kLatest) + ".partial");
    std::ofstream(temporary) << folder.filename().string() << '\n';
    std::filesystem::rename(temporary, parent / kLatest);
  }
  // Folder names sort by time (fixed decimals, same width while t < 10 s; compare as numbers).
  std::vector<std::pair<double, std::filesystem::path>> complete;
  for (const auto& entry : std::filesystem::directory_iterator(parent)) {
    const auto name = entry.path().filename().string();
    if (!entry.is_directory() || name.rfind(kFolderPrefix, 0) != 0) continue;
    if (!std::filesystem::exists(entry.path() / kComplete)) continue;
    complete.emplace_back(std::stod(name.substr(2)), entry.path());
  }
  std::sort(complete.begin(), complete.end(),
            [](const auto& a, const auto& b) { return a.first > b.first; });
  for (std::size_t k = static_cast<std::size_t>(std::max(keep, 1)); k < complete.size(); ++k) {
    std::error_code ignored;
    std::filesystem::remove_all(complete[k].second, ignored);
  }
}

}  // namespace valvefsi::coupler
