#pragma once
// The coupling schemes run in one process on two ModelParticipants, without transport: the
// reference the coupler program is tested against, and the loop the model-problem tests use.
//   serial explicit:   loads = fluid(motion_n); motion_{n+1} = solid(loads)
//   parallel explicit: loads_{n+1} = fluid(motion_n), motion_{n+1} = solid(loads_n)
//   implicit:          repeat the window (restore both) on x_{k+1} = accelerate(x_k, solid(fluid(x_k)))
//                      until relative_residual < tolerance; x_0 = motion_n.

#include "valvefsi/coupling/acceleration.hpp"
#include "valvefsi/coupling/model_problems/model_participant.hpp"

#include <string_view>
#include <vector>

namespace valvefsi::coupling::model {

enum class CouplingScheme { serial_explicit, parallel_explicit, implicit };
CouplingScheme parse_coupling_scheme(std::string_view name);  // "serial-explicit" | "parallel-explicit" | "implicit"

struct CouplingLoopOptions {
  CouplingScheme scheme = CouplingScheme::serial_explicit;
  double window = 1e-4;            // s
  int windows = 100;
  AccelerationOptions acceleration;  // implicit only
  double tolerance = 1e-10;        // relative residual, implicit only
  int max_iterations = 100;        // per window, implicit only
  double divergence_bound = 1e6;   // stop when |motion| exceeds this (or is not finite)
};

struct WindowRecord {
  double time = 0.0;         // at the window's end, s
  Eigen::VectorXd motion;    // solid data at the window's end
  Eigen::VectorXd loads;     // fluid data at the window's end
  int iterations = 1;
  double residual = 0.0;     // last relative residual (implicit)
};

struct CouplingRun {
  std::vector<WindowRecord> windows;
  bool diverged = false;           // motion left the bound or became NaN
  bool all_windows_converged = true;  // implicit: every window met the tolerance
};

CouplingRun run_in_process(ModelParticipant& fluid, ModelParticipant& solid, const CouplingLoopOptions& options);

}  // namespace valvefsi::coupling::model
