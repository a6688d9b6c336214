#pragma once
// Explicit central-difference dynamics of the brick model with lumped mass, shaped like
// ShellSolver (docs/solid_fe-hexahedron.md): advance_window(t_end, forces), state(), restore().
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "valvefsi/solid/hexahedron_element.hpp"
#include "valvefsi/solid/hexahedron_material.hpp"
#include "valvefsi/solid/mesh.hpp"
#include "valvefsi/solid/shell_solver.hpp"  // SymmetryConstraint

namespace valvefsi::solid {

struct HexahedronModelOptions {
  double density = 1100.0;                // kg/m^3
  std::vector<std::int64_t> fixed_nodes;  // nodes held in place
};

struct HexahedronModel {
  std::vector<HexElement> elements;
  Eigen::Matrix3Xd reference_positions;
  Eigen::VectorXd nodal_mass;        // rho V0 / 8 from each brick (kg)
  std::vector<std::uint8_t> fixed;   // 1 for fixed nodes
  double density = 1100.0;
};

// Builds the bricks of `mesh.hexahedra` with their axes; errors name `source`, the element and the value.
HexahedronModel build_hexahedron_model(const Mesh& mesh, const HexahedronModelOptions& options,
                                       const std::string& source);

// A quadrilateral face loaded by pressure: force dp * (area vector by the right-hand rule of its
// node order), distributed consistently over its four nodes.
using PressureFace = std::array<std::int64_t, 4>;

// The ventricular (inflow-side) faces 0-1-2-3 of `elements` (all bricks when empty) that are not
// the aortic face 4-7 of another brick: the outer surface a positive transvalvular pressure
// pushes toward the outflow side. Their right-hand normals point into the brick, i.e. to +normal.
std::vector<PressureFace> ventricular_faces(const Mesh& mesh, const std::vector<std::int64_t>& elements = {});

struct HexahedronEnergy {
  double kinetic = 0;           // (J)
  double internal_work = 0;     // work of all internal forces, hourglass included (J)
  double hourglass_work = 0;    // of which the hourglass forces (J)
  double strain_energy = 0;     // hyperelastic energy of the current state (J)
  double hourglass_energy = 0;  // 1/2 sum k q^2 of the current state (J)
  double external_work = 0;     // pressure and nodal forces (J)
  double damping_work = 0;      // mass-proportional damping (J)
  double contact_work = 0;      // contact-plane penalties (J)
  double initial_kinetic = 0;
  // KE + W_int + W_damp + W_contact - W_ext - KE0: zero for exact time integration.
  double balance() const {
    return kinetic + internal_work + damping_work + contact_work - external_work - initial_kinetic;
  }
  double relative_balance_error() const;  // |balance| over the largest energy term
};

struct HexahedronState {
  double time = 0;
  std::int64_t step = 0;
  Eigen::Matrix3Xd position;            // x at `time`
  Eigen::Matrix3Xd half_step_velocity;  // v at time - dt/2
  Eigen::Matrix3Xd velocity;            // v at `time`
  Eigen::Matrix3Xd internal_force;      // at `position`, hourglass included
  Eigen::Matrix3Xd hourglass_force;     // the hourglass part
  Eigen::Matrix3Xd external_force;
  Eigen::Matrix3Xd contact_force;
  std::vector<HexModuli> moduli;        // hourglass moduli per element (refreshed with the step)
  std::int64_t nodes_in_contact = 0;
  double last_step = 0;
  double stable_step = 0;               // safety applied
  std::int64_t critical_element = -1;
  HexahedronEnergy energy;
};

struct HexahedronSolverOptions {
  double time_step_safety = 0.8;         // fraction of the estimated critical step
  int time_step_update_interval = 10;    // steps between stable-step (and hourglass moduli) estimates
  double mass_damping_per_s = 0.0;       // alpha of the damping force alpha m v (off when 0)
  double max_time_step = 1e-4;           // s
  double contact_stiffness_factor = 0.1; // plane penalty k = factor m omega_max^2 per node
};

class HexahedronSolver {
 public:
  HexahedronSolver(HexahedronModel model, SolidMaterial material, HexahedronSolverOptions options = {});

  // Follower pressure dp(t) (Pa) on `faces`.
  void set_pressure(std::function<double(double)> pressure_Pa, std::vector<PressureFace> faces);
  void add_symmetry_constraints(const std::vector<SymmetryConstraint>& constraints);
  // Rigid plane no node may cross (normal towards the side where the leaflet lives); node penalty.
  void add_contact_plane(const Plane& plane);
  void set_velocity(const Eigen::Matrix3Xd& velocity);  // initial condition

  // Advances to exactly t_end under `nodal_forces` (3 x nodes, N, constant over the window) added
  // to the pressure load. Throws MaterialStateError naming the element, time and step on failure.
  void advance_window(double t_end, const Eigen::Matrix3Xd* nodal_forces = nullptr);

  const HexahedronState& state() const { return state_; }
  void restore(const HexahedronState& saved) { state_ = saved; internal_force_current_ = true; }
  const HexahedronModel& model() const { return model_; }
  const SolidMaterial& material() const { return material_; }
  const HexahedronSolverOptions& options() const { return options_; }
  Eigen::Matrix3Xd displacement() const { return state_.position - model_.reference_positions; }

  // Per-element maximum principal Cauchy stress (Pa) and logarithmic strain at the element centre,
  // the one integration point (what the reference's one-point bricks report).
  void element_fields(Eigen::VectorXd& max_principal_stress, Eigen::VectorXd& max_principal_log_strain) const;
  // The same on the two faces zeta = -1, +1 (the leaflet's surfaces, bending included), larger of
  // the two, from the trilinear gradient with the sheet's plane-stress law.
  void surface_fields(Eigen::VectorXd& max_principal_stress, Eigen::VectorXd& max_principal_log_strain) const;

  // For tests: forces the next step to use dt = factor x the critical-step estimate (safety 1).
  void set_step_factor_for_testing(double factor) { step_factor_ = factor; }

 private:
  void compute_internal_force(bool estimate_step);
  void compute_external_force(double t, const Eigen::Matrix3Xd* nodal_forces);
  void compute_contact_force();
  void apply_constraints(Eigen::Matrix3Xd& field) const;
  void update_kinetic_energy();
  void fields(Eigen::VectorXd& max_principal_stress, Eigen::VectorXd& max_principal_log_strain, bool surfaces) const;

  HexahedronModel model_;
  SolidMaterial material_;
  HexahedronSolverOptions options_;
  std::function<double(double)> pressure_;
  std::vector<PressureFace> pressure_faces_;
  std::vector<SymmetryConstraint> symmetry_;
  std::vector<Plane> contact_planes_;
  double contact_omega2_ = 0.0;
  double step_factor_ = 0.0;  // 0: use the safety factor
  std::vector<Eigen::Matrix3Xd> thread_forces_;
  std::vector<Eigen::Matrix3Xd> thread_hourglass_;
  Eigen::Matrix3Xd acceleration_;
  Eigen::Matrix3Xd previous_half_velocity_;
  bool internal_force_current_ = false;
  HexahedronState state_;
};

}  // namespace valvefsi::solid
