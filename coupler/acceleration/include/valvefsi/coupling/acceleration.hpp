#pragma once
// Acceleration of the implicit coupling fixed point x = H(x) within one time window:
// constant under-relaxation, Aitken's dynamic relaxation, and IQN-ILS (interface
// quasi-Newton with least-squares Jacobian approximation). See docs/coupling-numerics.md.

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <vector>
#include <string_view>

namespace valvefsi::coupling {

enum class AccelerationKind { constant_relaxation, aitken, iqn_ils };

struct AccelerationOptions {
  AccelerationKind kind = AccelerationKind::iqn_ils;
  double relaxation = 0.5;        // omega for constant; initial omega for Aitken and IQN-ILS's first step
  int reused_windows = 0;         // IQN-ILS: columns kept from this many past windows
  int max_columns = 100;          // IQN-ILS
  double filter_epsilon = 1e-10;  // IQN-ILS QR filter
};

// What an acceleration carries from one window to the next (IQN-ILS's reused columns), so a
// restarted run continues exactly; empty for schemes that start every window afresh.
struct CarriedState {
  std::vector<Eigen::VectorXd> vectors;
  std::vector<std::int64_t> integers;
};

// Fixed-point iteration x = H(x) on the interface vector (the solid's motion), per window.
class Acceleration {
 public:
  virtual ~Acceleration() = default;
  virtual void begin_window() = 0;   // a new window starts (reset per-window history)
  // input: x_k fed to the coupled operator; output: H(x_k). Returns x_{k+1}.
  virtual Eigen::VectorXd next_input(const Eigen::VectorXd& input, const Eigen::VectorXd& output) = 0;
  virtual void end_window() = 0;     // the window converged (IQN-ILS may keep columns)
  // Between windows (after end_window, before begin_window): the carried state and back.
  virtual CarriedState carried_state() const { return {}; }
  virtual void restore_carried_state(const CarriedState& /*state*/) {}
};

// Throws std::invalid_argument for out-of-range options (naming the field, value and range).
std::unique_ptr<Acceleration> make_acceleration(const AccelerationOptions& options);

// "constant" | "aitken" | "iqn-ils"; throws std::invalid_argument naming the allowed values
AccelerationKind parse_acceleration_kind(std::string_view name);

// |H(x)-x| / max(|H(x)|, tiny)
double relative_residual(const Eigen::VectorXd& input, const Eigen::VectorXd& output);

}  // namespace valvefsi::coupling
