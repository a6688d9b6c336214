#pragma once
// The coupling schemes: the order in which the fluid and the solid advance through each
// window and what each receives (docs/coupling.md has the diagrams).
//   serial explicit   : solid state at the window start -> fluid -> loads -> solid
//   parallel explicit : fluid (solid state at the start) and solid (previous window's loads) at once
//   serial implicit   : serial, repeated from checkpoints until the solid's end-of-window
//                       displacement converges; the acceleration proposes the next iterate

#include <Eigen/Core>

#include <cstdint>
#include <functional>

#include "valvefsi/coupler/coupler_settings.hpp"
#include "valvefsi/coupler/window_exchange.hpp"

namespace valvefsi::coupler {

// What one window transferred, for the interface time series.
struct WindowRecord {
  double time_end = 0.0;
  double size = 0.0;
  std::uint64_t index = 0;
  int iterations = 1;
  double relative_residual = 0.0;   // 0 for explicit schemes
  double first_residual = 0.0;      // implicit: the residual of the window's first iteration
  double smallest_residual = 0.0;   // implicit: the smallest over the window's iterations
  bool converged = true;
  Eigen::Vector3d force_fluid = Eigen::Vector3d::Zero();  // sum over the fluid's points (N)
  Eigen::Vector3d force_solid = Eigen::Vector3d::Zero();  // sum over the solid's nodes (N)
  double power_fluid = 0.0;   // sum f . v at the fluid's points (W)
  double power_solid = 0.0;   // sum f . v at the solid's nodes (W)
  // sum f . (x_end - x_start) at the solid's nodes (J): the loads' work on the solid over the
  // window, which power_solid x size (the velocity at the window's start) only approximates
  double load_work_solid = 0.0;
  double interface_oscillation = 0.0;  // m/s, the last block's (OscillationWatch)
};

struct SchemeSummary {
  std::uint64_t windows = 0;
  long total_iterations = 0;
  std::uint64_t unconverged_windows = 0;
  double final_time = 0.0;
};

using WindowObserver = std::function<void(const WindowRecord&)>;

// Size of the window starting at `time`: the smallest of the case's window and the positive
// proposals, cut (or stretched by a sliver) to land exactly on end_time.
double next_window_size(double time, double end_time, double case_window, double fluid_proposal,
                        double solid_proposal);

// Runs windows from t = 0 to settings.end_time. Throws the transport's errors, and
// coupling::CouplingFailed (after `observe` has seen the window) when an implicit window
// diverged or the solid's interface ran away (settings.divergence_residual,
// settings.max_interface_speed, settings.runaway_oscillation_speed).
SchemeSummary run_coupling_scheme(WindowExchange& exchange, const CouplerSettings& settings,
                                  const WindowObserver& observe);

}  // namespace valvefsi::coupler
