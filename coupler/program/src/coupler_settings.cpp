#include "valvefsi/coupler/coupler_settings.hpp"

#include <fmt/format.h>

#include "valvefsi/coupling/endpoint.hpp"

namespace valvefsi::coupler {

std::string scheme_label(const CouplerSettings& settings) {
  switch (settings.scheme) {
    case SchemeKind::serial_explicit: return "serial-explicit";
    case SchemeKind::parallel_explicit: return "parallel-explicit";
    case SchemeKind::serial_implicit: break;
  }
  switch (settings.acceleration.kind) {
    case coupling::AccelerationKind::constant_relaxation:
      return fmt::format("serial-implicit/constant-relaxation({})", settings.acceleration.relaxation);
    case coupling::AccelerationKind::aitken: return "serial-implicit/aitken";
    case coupling::AccelerationKind::iqn_ils: return "serial-implicit/iqn-ils";
  }
  return "serial-implicit";
}

CouplerSettings settings_from_case(const cases::Case& run_case, const std::filesystem::path& output_dir) {
  const auto& coupling = run_case.coupling();
  CouplerSettings settings;
  switch (coupling.scheme()) {
    case cases::CouplingCase::PARALLEL_EXPLICIT: settings.scheme = SchemeKind::parallel_explicit; break;
    case cases::CouplingCase::SERIAL_IMPLICIT: settings.scheme = SchemeKind::serial_implicit; break;
    default: settings.scheme = SchemeKind::serial_explicit; break;
  }
  switch (coupling.acceleration()) {
    case cases::CouplingCase::AITKEN: settings.acceleration.kind = coupling::AccelerationKind::aitken; break;
    case cases::CouplingCase::IQN_ILS: settings.acceleration.kind = coupling::AccelerationKind::iqn_ils; break;
    default: settings.acceleration.kind = coupling::AccelerationKind::constant_relaxation; break;
  }
  settings.acceleration.relaxation = coupling.relaxation_factor();
  settings.acceleration.reused_windows = coupling.iqn_reused_windows();
  settings.acceleration.filter_epsilon = coupling.iqn_filter_epsilon();
  settings.relative_tolerance = coupling.relative_tolerance();
  settings.absolute_tolerance = coupling.absolute_tolerance();
  settings.max_iterations = coupling.max_iterations();
  settings.window_size = coupling.window_size();
  settings.end_time = run_case.run().end_time();
  switch (coupling.mapping()) {
    case cases::CouplingCase::NEAREST_NEIGHBOUR: settings.mapping.method = coupling::MappingMethod::nearest_neighbor; break;
    case cases::CouplingCase::RBF: settings.mapping.method = coupling::MappingMethod::radial_basis; break;
    default: settings.mapping.method = coupling::MappingMethod::nearest_projection; break;
  }
  settings.mapping.rbf_support_radius = coupling.rbf_support_radius();
  settings.output_dir = output_dir;
  settings.endpoint = coupling::resolve_endpoint(coupling.endpoint(), output_dir);
  settings.liveness.heartbeat_interval = std::chrono::duration<double>(coupling.heartbeat_interval_s());
  settings.liveness.peer_timeout = std::chrono::duration<double>(coupling.peer_timeout_s());
  settings.liveness.startup_timeout = std::chrono::duration<double>(coupling.startup_timeout_s());
  const std::filesystem::path series = coupling.series_file();
  settings.series_file = series.is_absolute() ? series : output_dir / series;
  settings.series_flush_rows = coupling.series_flush_rows();
  settings.restart_interval = coupling.restart_interval_s();
  settings.restart_keep = coupling.restart_keep();
  settings.divergence_residual = coupling.divergence_residual();
  settings.max_interface_speed = coupling.max_interface_speed();
  settings.runaway_oscillation_speed = coupling.runaway_oscillation_speed();
  settings.runaway_growing_blocks = coupling.runaway_growing_blocks();
  settings.runaway_standing_speed = coupling.runaway_standing_speed();
  settings.runaway_standing_blocks = coupling.runaway_standing_blocks();
  settings.explicit_motion_previous_window_mean =
      coupling.explicit_motion_velocity() == cases::CouplingCase::PREVIOUS_WINDOW_MEAN;
  return settings;
}

}  // namespace valvefsi::coupler
