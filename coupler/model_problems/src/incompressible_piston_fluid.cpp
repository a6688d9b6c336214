#include "valvefsi/coupling/model_problems/incompressible_piston_fluid.hpp"

#include "parameter_checks.hpp"

namespace valvefsi::coupling::model {

IncompressiblePistonFluid::IncompressiblePistonFluid(const IncompressiblePistonFluidParameters& parameters)
    : parameters_(parameters) {
  const std::string model = "incompressible piston fluid";
  require_positive(model, "density", parameters.density);
  require_positive(model, "column_length", parameters.column_length);
  require_positive(model, "area", parameters.area);
  require_in(model, "newmark_beta", parameters.newmark_beta, 1e-6, 0.5);
  require_in(model, "newmark_gamma", parameters.newmark_gamma, 0.5, 1.0);
  state_.displacement = parameters.initial_displacement;
  state_.velocity = parameters.initial_velocity;
  state_.acceleration = parameters.initial_acceleration;
  saved_ = state_;
}

double IncompressiblePistonFluid::added_mass() const {
  return parameters_.density * parameters_.column_length * parameters_.area;
}

Eigen::VectorXd IncompressiblePistonFluid::current_data() const {
  return Eigen::VectorXd::Constant(1, -parameters_.area * parameters_.far_end_pressure - added_mass() * state_.acceleration);
}

Eigen::VectorXd IncompressiblePistonFluid::advance(double window, const Eigen::VectorXd& piston_motion) {
  require_positive("incompressible piston fluid", "window", window);
  require_size("incompressible piston fluid", "piston motion", piston_motion, 2);
  const double beta = parameters_.newmark_beta, gamma = parameters_.newmark_gamma, dt = window;
  const double predicted_u = state_.displacement + dt * state_.velocity + (0.5 - beta) * dt * dt * state_.acceleration;
  const double predicted_v = state_.velocity + (1.0 - gamma) * dt * state_.acceleration;
  // The whole column moves with the piston: its acceleration follows from the piston's displacement.
  const double a = (piston_motion(0) - predicted_u) / (beta * dt * dt);
  state_.displacement = piston_motion(0);
  state_.velocity = predicted_v + gamma * dt * a;
  state_.acceleration = a;
  state_.time += dt;
  return current_data();
}

double incompressible_piston_relaxation_limit(double added_mass, double structure_mass, double stiffness,
                                              double newmark_beta, double window) {
  return 2.0 / (1.0 + added_mass / (structure_mass + newmark_beta * stiffness * window * window));
}

}  // namespace valvefsi::coupling::model
