#pragma once
// The coupling window a fluid proposes so that each window is a whole number of its steps
// (fluid.fit_coupling_window_to_steps): the fluid sub-cycles a window with its stable step and
// clips the last step to the window's end, so a window of 2.06 stable steps costs 3 steps.
#include <algorithm>
#include <cmath>

namespace valvefsi::fluid {

struct CouplingWindowFit {
  // The step is shrunk by this factor so a step that shrinks a little within the window does
  // not add a sliver step.
  double step_margin = 0.97;
  // Propose only when it saves at least this fraction of the steps per simulated second: each
  // window also costs a solid advance and an exchange.
  double least_saving = 0.1;
};

// The window to propose (s) for the next window, or 0 for none (the case's window suits):
// the largest whole number of margin-shrunk stable steps within `case_window`.
inline double fitted_coupling_window(double stable_step, double case_window,
                                     const CouplingWindowFit& fit = {}) {
  if (!(stable_step > 0.0) || !(case_window > 0.0)) return 0.0;
  const double step = fit.step_margin * stable_step;
  const double whole_steps = std::floor(case_window / step);
  if (whole_steps < 1.0) return 0.0;  // one clipped step per window already
  const double steps_in_case_window = std::ceil(case_window / stable_step * (1.0 - 1e-12));
  const double case_step = case_window / steps_in_case_window;
  if (step < (1.0 + fit.least_saving) * case_step) return 0.0;
  return whole_steps * step;
}

// Learns the margin from the windows it planned: the step limit (the fastest particle's speed
// and acceleration, the leaflet's node speed, which changes with each window's motion) moves
// within a window by more in some phases than in others. A window that needed more steps than
// planned shrinks the margin by 0.02, one that did not grows it by 0.002 (to at most 0.99), so
// about one planned window in eleven takes a sliver step; the margin stays within [0.8, 0.99].
class CouplingWindowFitter {
 public:
  explicit CouplingWindowFitter(double case_window, CouplingWindowFit fit = {})
      : case_window_(case_window), fit_(fit) {}
  // After each window: the stable step the fluid would take next and the steps the window took.
  double propose(double stable_step, long steps_taken) {
    if (planned_steps_ > 0) {
      const bool overran = steps_taken > planned_steps_;
      if (overran) ++overruns_;
      fit_.step_margin = std::clamp(fit_.step_margin + (overran ? -0.02 : 0.002), 0.8, 0.99);
    }
    ++windows_;
    steps_ += steps_taken;
    const double proposal = fitted_coupling_window(stable_step, case_window_, fit_);
    planned_steps_ = proposal > 0.0 ? std::lround(proposal / (fit_.step_margin * stable_step)) : 0;
    return proposal;
  }
  [[nodiscard]] double mean_steps_per_window() const {
    return windows_ > 0 ? static_cast<double>(steps_) / static_cast<double>(windows_) : 0.0;
  }
  [[nodiscard]] long overruns() const { return overruns_; }
  [[nodiscard]] double margin() const { return fit_.step_margin; }

 private:
  double case_window_;
  CouplingWindowFit fit_;
  long planned_steps_ = 0;
  long windows_ = 0, steps_ = 0, overruns_ = 0;
};

}  // namespace valvefsi::fluid
