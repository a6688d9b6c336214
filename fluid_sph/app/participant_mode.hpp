#pragma once
// fluid_sph as the fluid participant of a coupled run (docs/writing-a-participant.md): the
// solid's interface surface becomes the immersed-surface model (2D: the two-sided thin wall),
// the surface nodes are the fluid's interface points, and every coupling window moves the
// surface to the coupler's target, advances the fluid to the window's end and returns the
// window-averaged force of the fluid on each node.
#include <filesystem>

#include "case.pb.h"

namespace valvefsi::fluid::app {

// Returns the process exit code (0, or the coupling library's codes: 2 bad input, 3 peer lost,
// 4 protocol error, 5 aborted; 1 for a fluid failure).
int run_participant(const cases::Case& c, const std::filesystem::path& case_file, const std::filesystem::path& output);

}  // namespace valvefsi::fluid::app
