#pragma once
// The folder layout of restart points, shared by the coupler and by programs that restart on
// their own (FE-only solid): OUTPUT/restart/t_<time>/<program>.restart.h5, a COMPLETE mark once
// every file of the point is written, OUTPUT/restart/LATEST naming the newest complete point,
// and only the newest `keep` complete points kept. docs/coupling.md, "Restarts".
#include <filesystem>
#include <initializer_list>
#include <string_view>

namespace valvefsi::coupling {

// OUTPUT/restart/t_<time, 9 decimals>.
std::filesystem::path restart_folder(const std::filesystem::path& output_dir, double time);

// Marks `folder` complete, points LATEST (in its parent) at it and removes older complete
// folders beyond `keep` (at least 1 is kept).
void mark_restart_complete(const std::filesystem::path& folder, int keep);

// The restart point behind what a user gives: a complete restart folder, or a run's restart/
// folder (its LATEST). Checks that every program named in `programs` has its file there.
// Throws std::runtime_error starting with `option` (e.g. "--restart") and the given path,
// saying what is missing.
std::filesystem::path resolve_restart_folder(const std::filesystem::path& given,
                                             std::initializer_list<std::string_view> programs,
                                             std::string_view option = "--restart");

}  // namespace valvefsi::coupling
