#pragma once
// solid_fe as the coupler's structure participant (docs/solid_fe.md, "Participant mode").
#include <filesystem>

#include "case.pb.h"

namespace valvefsi::solid {

// Runs the coupled mode to the coupler's end; returns the process exit code (0, the
// participant library's transport codes 2-5, or 6 when the solid itself fails).
int run_participant(const cases::Case& c, const std::filesystem::path& case_file,
                    const std::filesystem::path& output_dir);

}  // namespace valvefsi::solid
