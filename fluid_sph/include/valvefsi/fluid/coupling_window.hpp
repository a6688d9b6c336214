#pragma once
// The coupling window a fluid proposes so that each window is a whole number of its steps
// (fluid.fit_coupling_window_to_steps): the fluid sub-cycles a window with its stable step and
// clips the last step to the window's end, so a window of 2.06 stable steps costs 3 steps.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <deque>

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

// Proposes from the smallest stable step of the last few windows: the leaflet's node speed,
// which limits the step, changes with each window's motion, after the proposal was made.
class CouplingWindowFitter {
 public:
  explicit CouplingWindowFitter(double case_window, std::size_t memory = 8,
                                CouplingWindowFit fit = {})
      : case_window_(case_window), memory_(memory), fit_(fit) {}
  // After each window: the stable step the fluid would take next and the steps the window took.
  double propose(double stable_step, long steps_taken) {
    recent_.push_back(stable_step);
    if (recent_.size() > memory_) recent_.pop_front();
    ++windows_;
    steps_ += steps_taken;
    return fitted_coupling_window(*std::min_element(recent_.begin(), recent_.end()), case_window_,
                                  fit_);
  }
  [[nodiscard]] double mean_steps_per_window() const {
    return windows_ > 0 ? static_cast<double>(steps_) / static_cast<double>(windows_) : 0.0;
  }

 private:
  double case_window_;
  std::size_t memory_;
  CouplingWindowFit fit_;
  std::deque<double> recent_;
  long windows_ = 0, steps_ = 0;
};

}  // namespace valvefsi::fluid
