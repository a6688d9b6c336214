#pragma once
// Aitken's dynamic relaxation (Kuettler & Wall 2008): with residuals r_k = H(x_k) - x_k,
//   omega_k = -omega_{k-1} r_{k-1}.(r_k - r_{k-1}) / |r_k - r_{k-1}|^2,  x_{k+1} = x_k + omega_k r_k.
// Each window starts again from the initial omega.

#include "valvefsi/coupling/acceleration.hpp"

namespace valvefsi::coupling {

class AitkenAcceleration final : public Acceleration {
 public:
  explicit AitkenAcceleration(double initial_omega) : initial_omega_(initial_omega) {}
  void begin_window() override;
  Eigen::VectorXd next_input(const Eigen::VectorXd& input, const Eigen::VectorXd& output) override;
  void end_window() override {}

 private:
  double initial_omega_;
  double omega_ = 0.0;
  bool has_previous_ = false;
  Eigen::VectorXd previous_residual_;
};

}  // namespace valvefsi::coupling
