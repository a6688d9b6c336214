#include "valvefsi/coupling/restart_points.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "valvefsi/coupling/restart_file.hpp"

namespace valvefsi::coupling {

namespace {

constexpr const char* kComplete = "COMPLETE";
constexpr const char* kLatest = "LATEST";
constexpr const char* kFolderPrefix = "t_";

}  // namespace

std::filesystem::path restart_folder(const std::filesystem::path& output_dir, double time) {
  return output_dir / "restart" / fmt::format("{}{:.9f}", kFolderPrefix, time);
}

void mark_restart_complete(const std::filesystem::path& folder, int keep) {
  std::ofstream(folder / kComplete) << "complete\n";
  const auto parent = folder.parent_path();
  {
    // Written aside and renamed, so a reader never sees a half-written LATEST.
    const auto temporary = parent / (std::string(kLatest) + ".partial");
    std::ofstream(temporary) << folder.filename().string() << '\n';
    std::filesystem::rename(temporary, parent / kLatest);
  }
  // Folder names sort by time only while t < 10 s at fixed width: compare as numbers.
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

std::filesystem::path resolve_restart_folder(const std::filesystem::path& given,
                                             std::initializer_list<std::string_view> programs,
                                             std::string_view option) {
  if (!std::filesystem::is_directory(given))
    throw std::runtime_error(fmt::format("{} {}: no such folder", option, given.string()));
  std::filesystem::path folder = given;
  if (!std::filesystem::exists(given / kComplete)) {
    std::ifstream latest(given / kLatest);
    std::string name;
    if (!(latest >> name)) {
      throw std::runtime_error(
          fmt::format("{} {}: neither a complete restart folder (no {} mark) nor a run's "
                      "restart/ folder (no {} file)",
                      option, given.string(), kComplete, kLatest));
    }
    folder = given / name;
    if (!std::filesystem::exists(folder / kComplete))
      throw std::runtime_error(fmt::format("{} {}: {} names {}, which is not complete", option,
                                           given.string(), kLatest, folder.string()));
  }
  for (const auto program : programs) {
    const auto file = restart_file_path(folder, program);
    if (!std::filesystem::exists(file))
      throw std::runtime_error(
          fmt::format("{} {}: {} is missing", option, given.string(), file.string()));
  }
  return folder;
}

}  // namespace valvefsi::coupling
