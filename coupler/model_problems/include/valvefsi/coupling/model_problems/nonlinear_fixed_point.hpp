#pragma once
// A stateless nonlinear pair with a known root, for testing quasi-Newton coupling end to end:
//   "fluid":  y = F(x) = B x + 0.5 tanh(x)            (componentwise tanh)
//   "solid":  x = S(y) = x* + A (y - F(x*))
// so H = S o F has the fixed point x*, and dH/dx(x*) = A (B + 0.5 diag(1 - tanh^2 x*)).
// The default A, B make that Jacobian non-contractive (spectral radius > 1), so plain
// (omega = 1) iteration diverges while IQN-ILS converges in a bounded number of iterations.

#include "valvefsi/coupling/model_problems/model_participant.hpp"

#include <utility>

namespace valvefsi::coupling::model {

struct NonlinearFixedPoint {
  Eigen::VectorXd root;  // x*
  Eigen::MatrixXd a, b;
  static NonlinearFixedPoint standard();  // 3 unknowns, dH/dx(x*) with eigenvalues below -1 and above +1
  Eigen::VectorXd fluid(const Eigen::VectorXd& x) const;
  Eigen::VectorXd solid(const Eigen::VectorXd& y) const;
  Eigen::MatrixXd jacobian_at_root() const;
};

class NonlinearFixedPointFluid final : public ModelParticipant {
 public:
  explicit NonlinearFixedPointFluid(NonlinearFixedPoint problem) : problem_(std::move(problem)) {}
  Eigen::VectorXd current_data() const override { return problem_.fluid(Eigen::VectorXd::Zero(problem_.root.size())); }
  Eigen::VectorXd advance(double window, const Eigen::VectorXd& x) override;
  void save_checkpoint() override { saved_time_ = time_; }
  void restore_checkpoint() override { time_ = saved_time_; }
  double time() const override { return time_; }
  Eigen::VectorXd state_values() const override { return Eigen::VectorXd::Constant(1, time_); }
  void load_state_values(const Eigen::VectorXd& values) override {
    require_state_size("NonlinearFixedPointFluid", values, 1);
    time_ = values(0);
  }

 private:
  NonlinearFixedPoint problem_;
  double time_ = 0.0, saved_time_ = 0.0;
};

class NonlinearFixedPointSolid final : public ModelParticipant {
 public:
  explicit NonlinearFixedPointSolid(NonlinearFixedPoint problem) : problem_(std::move(problem)) {}
  Eigen::VectorXd current_data() const override { return Eigen::VectorXd::Zero(problem_.root.size()); }
  Eigen::VectorXd advance(double window, const Eigen::VectorXd& y) override;
  void save_checkpoint() override { saved_time_ = time_; }
  void restore_checkpoint() override { time_ = saved_time_; }
  double time() const override { return time_; }
  Eigen::VectorXd state_values() const override { return Eigen::VectorXd::Constant(1, time_); }
  void load_state_values(const Eigen::VectorXd& values) override {
    require_state_size("NonlinearFixedPointSolid", values, 1);
    time_ = values(0);
  }

 private:
  NonlinearFixedPoint problem_;
  double time_ = 0.0, saved_time_ = 0.0;
};

}  // namespace valvefsi::coupling::model
