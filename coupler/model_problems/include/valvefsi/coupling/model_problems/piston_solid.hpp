#pragma once
// A rigid piston of mass m on a spring k, driven by a constant external force and by the
// fluid's force, integrated with Newmark (beta, gamma) using the end-of-window fluid force:
//   m a_{n+1} + k u_{n+1} = F_fluid + F_external.
// Default beta = 1/4, gamma = 1/2 (trapezoidal rule: second order, no numerical damping).

#include "valvefsi/coupling/model_problems/model_participant.hpp"

namespace valvefsi::coupling::model {

struct PistonSolidParameters {
  double mass = 1.0;              // kg (per unit area in the acoustic model: rho_s h_s, kg/m^2)
  double stiffness = 0.0;         // N/m
  double external_force = 0.0;    // N, along +x, constant in time
  double newmark_beta = 0.25;
  double newmark_gamma = 0.5;
  double initial_displacement = 0.0;  // m
  double initial_velocity = 0.0;      // m/s
  double initial_acceleration = 0.0;  // m/s^2, consistent with the initial forces (Newmark needs a_0)
};

class PistonSolid final : public ModelParticipant {
 public:
  explicit PistonSolid(const PistonSolidParameters& parameters);  // throws std::invalid_argument
  Eigen::VectorXd current_data() const override;
  Eigen::VectorXd advance(double window, const Eigen::VectorXd& fluid_force) override;
  void save_checkpoint() override { saved_ = state_; }
  void restore_checkpoint() override { state_ = saved_; }
  double time() const override { return state_.time; }
  Eigen::VectorXd state_values() const override {
    return Eigen::Vector4d(state_.time, state_.displacement, state_.velocity, state_.acceleration);
  }
  void load_state_values(const Eigen::VectorXd& values) override {
    require_state_size("PistonSolid", values, 4);
    state_ = {values(0), values(1), values(2), values(3)};
  }
  double acceleration() const { return state_.acceleration; }

 private:
  struct State {
    double time = 0.0, displacement = 0.0, velocity = 0.0, acceleration = 0.0;
  };
  PistonSolidParameters parameters_;
  State state_, saved_;
};

}  // namespace valvefsi::coupling::model
