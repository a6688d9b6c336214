#include "aitken_acceleration.hpp"

#include "constant_relaxation.hpp"

namespace valvefsi::coupling {

void AitkenAcceleration::begin_window() {
  has_previous_ = false;
  previous_residual_.resize(0);
}

Eigen::VectorXd AitkenAcceleration::next_input(const Eigen::VectorXd& input, const Eigen::VectorXd& output) {
  check_same_size(input, output);
  const Eigen::VectorXd residual = output - input;
  if (!has_previous_ || previous_residual_.size() != residual.size()) {
    omega_ = initial_omega_;
  } else {
    const Eigen::VectorXd change = residual - previous_residual_;
    const double change_squared = change.squaredNorm();
    // Two equal residuals carry no curvature information: keep the last omega.
    if (change_squared > 0.0) omega_ = -omega_ * previous_residual_.dot(change) / change_squared;
  }
  previous_residual_ = residual;
  has_previous_ = true;
  return input + omega_ * residual;
}

}  // namespace valvefsi::coupling
