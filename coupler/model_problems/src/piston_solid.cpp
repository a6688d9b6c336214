#include "valvefsi/coupling/model_problems/piston_solid.hpp"

#include "parameter_checks.hpp"

namespace valvefsi::coupling::model {

PistonSolid::PistonSolid(const PistonSolidParameters& parameters) : parameters_(parameters) {
  require_positive("piston solid", "mass", parameters.mass);
  require_at_least("piston solid", "stiffness", parameters.stiffness, 0.0);
  require_in("piston solid", "newmark_beta", parameters.newmark_beta, 0.0, 0.5);
  require_in("piston solid", "newmark_gamma", parameters.newmark_gamma, 0.5, 1.0);
  state_.displacement = parameters.initial_displacement;
  state_.velocity = parameters.initial_velocity;
  state_.acceleration = parameters.initial_acceleration;
  saved_ = state_;
}

Eigen::VectorXd PistonSolid::current_data() const {
  return Eigen::Vector2d(state_.displacement, state_.velocity);
}

Eigen::VectorXd PistonSolid::advance(double window, const Eigen::VectorXd& fluid_force) {
  require_positive("piston solid", "window", window);
  require_size("piston solid", "fluid force", fluid_force, 1);
  const double beta = parameters_.newmark_beta, gamma = parameters_.newmark_gamma, dt = window;
  const double predicted_u = state_.displacement + dt * state_.velocity + (0.5 - beta) * dt * dt * state_.acceleration;
  const double predicted_v = state_.velocity + (1.0 - gamma) * dt * state_.acceleration;
  // m a + k (u_pred + beta dt^2 a) = F_fluid + F_external
  const double a = (fluid_force(0) + parameters_.external_force - parameters_.stiffness * predicted_u) /
                   (parameters_.mass + beta * dt * dt * parameters_.stiffness);
  state_.displacement = predicted_u + beta * dt * dt * a;
  state_.velocity = predicted_v + gamma * dt * a;
  state_.acceleration = a;
  state_.time += dt;
  return current_data();
}

}  // namespace valvefsi::coupling::model

namespace valvefsi::coupling::model {

void require_state_size(const char* model, const Eigen::VectorXd& values, Eigen::Index expected) {
  if (values.size() != expected) {
    throw std::invalid_argument(std::string(model) + ": a restart state of " + std::to_string(values.size()) +
                                " values; this model has " + std::to_string(expected));
  }
}

}  // namespace valvefsi::coupling::model
