#pragma once
// Constant under-relaxation: x_{k+1} = x_k + omega (H(x_k) - x_k). For a linear operator with
// Jacobian eigenvalues lambda_i (all real, < 1) it converges iff 0 < omega < 2 / (1 - min lambda_i).

#include "valvefsi/coupling/acceleration.hpp"

namespace valvefsi::coupling {

void check_same_size(const Eigen::VectorXd& input, const Eigen::VectorXd& output);

class ConstantRelaxation final : public Acceleration {
 public:
  explicit ConstantRelaxation(double omega) : omega_(omega) {}
  void begin_window() override {}
  Eigen::VectorXd next_input(const Eigen::VectorXd& input, const Eigen::VectorXd& output) override {
    check_same_size(input, output);
    return input + omega_ * (output - input);
  }
  void end_window() override {}

 private:
  double omega_;
};

}  // namespace valvefsi::coupling
