#pragma once
// A 1D linear acoustic column x in [0, L] (density rho, sound speed c, cross-section A) in
// front of the piston at x = 0, in characteristic variables w+- = p +- rho c u, advanced by
// first-order upwinding with CFL = c dt / dx <= 1 (one step per window):
//   w+_i <- w+_i - CFL (w+_i - w+_{i-1}),   w-_i <- w-_i + CFL (w-_{i+1} - w-_i).
// The piston (velocity v) is a moving wall: the incoming invariant is w+ = w-_0 + 2 rho c v,
// and the pressure on it is p_wall = w-_0 + rho c v, so the force on the piston is -A p_wall.
// The far end is non-reflecting (w- = 0 enters), closed (u = 0) or open (p = p_far).
//
// With mu = rho c dt / m'' (the fluid mass a wave reaches in one window over the piston's mass
// per area m'' = rho_s h_s = m / A) and the trapezoidal piston, see acoustic_piston_limits().

#include "valvefsi/coupling/model_problems/model_participant.hpp"

#include <string_view>

namespace valvefsi::coupling::model {

enum class FarEnd { non_reflecting, closed, open };
FarEnd parse_far_end(std::string_view name);  // "non-reflecting" | "closed" | "open"

struct AcousticColumnParameters {
  double density = 1000.0;      // kg/m^3
  double sound_speed = 10.0;    // m/s
  double column_length = 0.1;   // m
  int cells = 100;
  double area = 1.0;            // m^2
  FarEnd far_end = FarEnd::non_reflecting;
  double far_end_pressure = 0.0;  // Pa (gauge), used by the open end
};

class AcousticColumnFluid final : public ModelParticipant {
 public:
  explicit AcousticColumnFluid(const AcousticColumnParameters& parameters);
  Eigen::VectorXd current_data() const override;
  // Uses the piston velocity in motion[1]; the window must satisfy CFL = c window / dx <= 1.
  Eigen::VectorXd advance(double window, const Eigen::VectorXd& piston_motion) override;
  void save_checkpoint() override { saved_ = state_; }
  void restore_checkpoint() override { state_ = saved_; }
  double time() const override { return state_.time; }
  // [time, wall pressure, w+ (cells), w- (cells)]
  Eigen::VectorXd state_values() const override;
  void load_state_values(const Eigen::VectorXd& values) override;
  double cell_size() const;
  Eigen::VectorXd pressure() const;  // cell pressures, Pa
  Eigen::VectorXd velocity() const;  // cell velocities, m/s

 private:
  struct State {
    double time = 0.0;
    double wall_pressure = 0.0;
    Eigen::VectorXd right_going, left_going;  // w+ and w-, Pa
  };
  AcousticColumnParameters parameters_;
  State state_, saved_;
};

// Analytic limits in mu = rho_f c dt / (rho_s h_s) = rho_f CFL dx / (rho_s h_s) for the
// trapezoidal piston (Newmark 1/4, 1/2) on the non-reflecting column (docs/coupling-numerics.md):
struct AcousticPistonLimits {
  double serial_explicit = 2.0;                  // |roots of z^2 - (1 - mu/2) z + mu/2| < 1
  double parallel_explicit = 0.8284271247461902; // 2 (sqrt 2 - 1): roots of z^3 - z^2 + mu/2 (z + 1)
  double implicit_without_relaxation = 2.0;      // omega = 1 < 2 / (1 + mu/2)
};
double acoustic_mass_ratio(double fluid_density, double sound_speed, double window, double structure_mass_per_area);

}  // namespace valvefsi::coupling::model
