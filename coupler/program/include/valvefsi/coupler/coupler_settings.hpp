#pragma once
// Everything the coupler program needs, taken from a case's `coupling` and `run` parts
// (proto/coupling_case.proto) and the command line.

#include <filesystem>
#include <string>

#include "case.pb.h"
#include "valvefsi/coupling/acceleration.hpp"
#include "valvefsi/coupling/interface_mapping.hpp"
#include "valvefsi/coupling/message_channel.hpp"

namespace valvefsi::coupler {

enum class SchemeKind { serial_explicit, parallel_explicit, serial_implicit };

struct CouplerSettings {
  SchemeKind scheme = SchemeKind::serial_explicit;
  coupling::AccelerationOptions acceleration;
  double relative_tolerance = 1e-4;
  double absolute_tolerance = 1e-9;  // m, RMS over the solid's nodes
  int max_iterations = 50;
  double window_size = 1e-3;   // s, the largest window
  double end_time = 0.0;       // s
  coupling::MappingOptions mapping;
  std::string endpoint;
  coupling::LivenessSettings liveness;
  std::filesystem::path output_dir;
  std::filesystem::path series_file;
  int series_flush_rows = 50;
  // Restarts (docs/coupling.md, "Restarts"): write every restart_interval s (0 = never) into
  // output_dir/restart/, keep the newest restart_keep; continue from restart_from if set.
  double restart_interval = 0.0;
  int restart_keep = 2;
  std::filesystem::path restart_from;   // a complete restart folder (resolve_restart_folder)
  double restart_time = 0.0;            // its time, read from the coupler's restart file
  // Failure checks (coupling.divergence_residual, max_interface_speed, runaway_oscillation_speed
  // with runaway_growing_blocks); 0 = off.
  double divergence_residual = 1.0;
  double max_interface_speed = 20.0;  // m/s
  double runaway_oscillation_speed = 0.5;  // m/s
  int runaway_growing_blocks = 12;
  double runaway_standing_speed = 0.0;  // m/s
  int runaway_standing_blocks = 8;
  // Explicit schemes: the fluid's points move with the solid's mean velocity over the previous
  // window instead of its velocity at the window's start (coupling.explicit_motion_velocity).
  bool explicit_motion_previous_window_mean = false;
};

// "serial-explicit", "parallel-explicit", "serial-implicit/iqn-ils" (the acceleration is part
// of an implicit scheme's name), as reported to participants and in logs.
std::string scheme_label(const CouplerSettings& settings);

// From a loaded (checked, defaults filled) case. `output_dir` is the run's folder (the
// command line's --output, or run.output_dir); the endpoint follows resolve_endpoint().
CouplerSettings settings_from_case(const cases::Case& run_case, const std::filesystem::path& output_dir);

}  // namespace valvefsi::coupler
