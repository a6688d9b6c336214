#include "valvefsi/coupling/model_problems/acoustic_column_fluid.hpp"

#include "parameter_checks.hpp"

#include <string>

namespace valvefsi::coupling::model {

FarEnd parse_far_end(std::string_view name) {
  if (name == "non-reflecting") return FarEnd::non_reflecting;
  if (name == "closed") return FarEnd::closed;
  if (name == "open") return FarEnd::open;
  throw std::invalid_argument("unknown far end '" + std::string(name) +
                              "'; allowed: \"non-reflecting\", \"closed\", \"open\"");
}

AcousticColumnFluid::AcousticColumnFluid(const AcousticColumnParameters& parameters) : parameters_(parameters) {
  const std::string model = "acoustic column";
  require_positive(model, "density", parameters.density);
  require_positive(model, "sound_speed", parameters.sound_speed);
  require_positive(model, "column_length", parameters.column_length);
  require_positive(model, "area", parameters.area);
  if (parameters.cells < 1) parameter_error(model, "cells", parameters.cells, "an integer >= 1");
  // At rest; an open end starts at its far pressure so that the column is in equilibrium.
  const double p0 = parameters.far_end == FarEnd::open ? parameters.far_end_pressure : 0.0;
  state_.right_going = Eigen::VectorXd::Constant(parameters.cells, p0);
  state_.left_going = Eigen::VectorXd::Constant(parameters.cells, p0);
  state_.wall_pressure = p0;
  saved_ = state_;
}

double AcousticColumnFluid::cell_size() const { return parameters_.column_length / parameters_.cells; }

Eigen::VectorXd AcousticColumnFluid::pressure() const { return 0.5 * (state_.right_going + state_.left_going); }

Eigen::VectorXd AcousticColumnFluid::velocity() const {
  return (state_.right_going - state_.left_going) / (2.0 * parameters_.density * parameters_.sound_speed);
}

Eigen::VectorXd AcousticColumnFluid::current_data() const {
  return Eigen::VectorXd::Constant(1, -parameters_.area * state_.wall_pressure);
}

Eigen::VectorXd AcousticColumnFluid::advance(double window, const Eigen::VectorXd& piston_motion) {
  require_positive("acoustic column", "window", window);
  require_size("acoustic column", "piston motion", piston_motion, 2);
  const double cfl = parameters_.sound_speed * window / cell_size();
  if (cfl > 1.0 + 1e-12) {
    parameter_error("acoustic column", "window (as CFL = c dt / dx)", cfl, "CFL <= 1 (one upwind step per window)");
  }
  const double impedance = parameters_.density * parameters_.sound_speed;  // rho c
  const double piston_velocity = piston_motion(1);
  Eigen::VectorXd& wp = state_.right_going;
  Eigen::VectorXd& wm = state_.left_going;
  const Eigen::Index n = wp.size();

  const double entering_at_piston = wm(0) + 2.0 * impedance * piston_velocity;
  double entering_at_far_end = 0.0;
  switch (parameters_.far_end) {
    case FarEnd::non_reflecting: entering_at_far_end = 0.0; break;
    case FarEnd::closed: entering_at_far_end = wp(n - 1); break;
    case FarEnd::open: entering_at_far_end = 2.0 * parameters_.far_end_pressure - wp(n - 1); break;
  }
  // Upwind differences, each from the side the wave comes from (old values on the right-hand side).
  const Eigen::VectorXd old_wp = wp, old_wm = wm;
  wp(0) -= cfl * (old_wp(0) - entering_at_piston);
  wp.tail(n - 1) -= cfl * (old_wp.tail(n - 1) - old_wp.head(n - 1));
  wm(n - 1) += cfl * (entering_at_far_end - old_wm(n - 1));
  wm.head(n - 1) += cfl * (old_wm.tail(n - 1) - old_wm.head(n - 1));

  state_.wall_pressure = wm(0) + impedance * piston_velocity;
  state_.time += window;
  return current_data();
}

double acoustic_mass_ratio(double fluid_density, double sound_speed, double window, double structure_mass_per_area) {
  return fluid_density * sound_speed * window / structure_mass_per_area;
}

}  // namespace valvefsi::coupling::model

namespace valvefsi::coupling::model {

Eigen::VectorXd AcousticColumnFluid::state_values() const {
  const Eigen::Index cells = state_.right_going.size();
  Eigen::VectorXd values(2 + 2 * cells);
  values << state_.time, state_.wall_pressure, state_.right_going, state_.left_going;
  return values;
}

void AcousticColumnFluid::load_state_values(const Eigen::VectorXd& values) {
  const Eigen::Index cells = state_.right_going.size();
  require_state_size("AcousticColumnFluid", values, 2 + 2 * cells);
  state_.time = values(0);
  state_.wall_pressure = values(1);
  state_.right_going = values.segment(2, cells);
  state_.left_going = values.segment(2 + cells, cells);
}

}  // namespace valvefsi::coupling::model
