#pragma once
// What the launcher (scripts/run_case.py) needs from a case, read with the real case loader so
// that the launcher never parses protobuf text itself: programs, their arguments, the output
// folder, the endpoint and whether the run is FE-only.

#include <filesystem>
#include <string>

#include "case.pb.h"

namespace valvefsi::coupler {

// A JSON object: {"output_dir", "endpoint", "fe_only", "fluid": {"executable", "arguments"},
// "solid": {...}, "coupler": {...}}. An executable written with a '/' is resolved against the
// case file's folder; a bare name (or "" = the default program) is left to the launcher.
std::string launch_plan_json(const std::filesystem::path& case_file, const cases::Case& run_case,
                             const std::filesystem::path& output_dir);

}  // namespace valvefsi::coupler
