#pragma once
// A whole coupled run in the coupler process: bind, start-up exchange, windows to the end
// time, interface time series, and a clean finish; or, on any fault, an Abort to every
// participant still reachable and the fault's exit code.

#include "valvefsi/coupler/coupler_settings.hpp"

namespace valvefsi::coupler {

// Returns the process exit code (coupling::ExitCode); logs the cause of any failure.
int run_coupler(const CouplerSettings& settings);

}  // namespace valvefsi::coupler
