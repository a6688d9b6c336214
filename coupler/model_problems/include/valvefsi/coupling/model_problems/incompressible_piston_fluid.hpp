#pragma once
// An incompressible fluid column (density rho, length L, cross-section A) in front of the
// piston, with a prescribed pressure p_far at its far end. Its force on the piston is
//   F = -A (p_far + rho L a_piston) = -A p_far - m_a a,   m_a = rho L A   (added mass),
// where a is the piston acceleration implied by the received displacement through the same
// Newmark relations the solid uses: a = (u - u_pred) / (beta dt^2).
//
// Dirichlet-Neumann iteration of one window on x = [u, v]: dH/dx has the eigenvalues 0 and
// -m_a / (m_s + beta k dt^2), so constant relaxation converges iff
//   0 < omega < 2 / (1 + m_a / (m_s + beta k dt^2))   (= 2 / (1 + m_a/m_s) for k = 0).

#include "valvefsi/coupling/model_problems/model_participant.hpp"

namespace valvefsi::coupling::model {

struct IncompressiblePistonFluidParameters {
  double density = 1000.0;       // kg/m^3
  double column_length = 0.1;    // m
  double area = 1e-4;            // m^2
  double far_end_pressure = 0.0; // Pa, constant
  double newmark_beta = 0.25;    // must match the solid's
  double newmark_gamma = 0.5;
  // The piston's initial kinematics, as the solid's (a_0 = (F_ext - A p_far) / (m_s + m_a) for k = 0).
  double initial_displacement = 0.0;  // m
  double initial_velocity = 0.0;      // m/s
  double initial_acceleration = 0.0;  // m/s^2
};

class IncompressiblePistonFluid final : public ModelParticipant {
 public:
  explicit IncompressiblePistonFluid(const IncompressiblePistonFluidParameters& parameters);
  double added_mass() const;  // rho L A, kg
  Eigen::VectorXd current_data() const override;
  Eigen::VectorXd advance(double window, const Eigen::VectorXd& piston_motion) override;
  void save_checkpoint() override { saved_ = state_; }
  void restore_checkpoint() override { state_ = saved_; }
  double time() const override { return state_.time; }
  Eigen::VectorXd state_values() const override {
    return Eigen::Vector4d(state_.time, state_.displacement, state_.velocity, state_.acceleration);
  }
  void load_state_values(const Eigen::VectorXd& values) override {
    require_state_size("IncompressiblePistonFluid", values, 4);
    state_ = {values(0), values(1), values(2), values(3)};
  }

 private:
  struct State {
    double time = 0.0, displacement = 0.0, velocity = 0.0, acceleration = 0.0;  // of the piston
  };
  IncompressiblePistonFluidParameters parameters_;
  State state_, saved_;
};

// The analytic relaxation limit above.
double incompressible_piston_relaxation_limit(double added_mass, double structure_mass, double stiffness,
                                              double newmark_beta, double window);

}  // namespace valvefsi::coupling::model
