#pragma once
// Explicit central-difference dynamics with lumped mass over any element model (element_model.hpp:
// shell triangles or 8-node bricks), docs/solid_fe.md "Dynamics". The time loop is one call,
// advance_window(t_end, forces): FE-only runs call it with the output times, the coupled
// participant with each coupling window's end. The whole state is the copyable SolverState, so
// save/restore is assignment. It keeps the energy ledger, sets the stable step (element bound,
// Lanczos calibration, growth limit), applies fixed nodes, mirror planes, strip ties and contact.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "valvefsi/solid/coaptation_tie.hpp"
#include "valvefsi/solid/element_model.hpp"
#include "valvefsi/solid/leaflet_contact.hpp"
#include "valvefsi/solid/mesh.hpp"

namespace valvefsi::solid {

struct EnergyBalance {
  double kinetic = 0;           // (J)
  double internal_work = 0;     // work of the internal forces (hourglass included) = stored + dissipated (J)
  double hourglass_work = 0;    // of which the hourglass forces (bricks) (J)
  double strain_energy = 0;     // hyperelastic energy of the current state (J), for comparison
  double hourglass_energy = 0;  // hourglass energy of the current state (bricks) (J)
  double external_work = 0;     // work of pressure and coupler forces (J)
  double damping_work = 0;      // dissipated by mass-proportional damping (J)
  double contact_work = 0;      // stored/dissipated in contact penalties (J)
  double tie_work = 0;          // done against coaptation ties: stored now + lost at releases (J)
  double tie_energy = 0;        // stored in the tied springs now (J)
  // Implicit dynamics only: energy the generalized-alpha scheme removes (J; negative: creates),
  // computed from each step's quantities by the scheme's energy identity (generalized_alpha.hpp),
  // so that the balance is the converged Newton residual's work; exactly 0 for rho_inf = 1 and
  // for the explicit integrator.
  double numerical_dissipation = 0;
  // Of numerical_dissipation, the part from the external load's steps at window starts:
  // (1/2 - alpha_f) dx . (F_new - F_old) of each window's first step, whose starting
  // acceleration still holds the old load. A lagged, stiffness-like load (the fluid's) makes it
  // negative: the scheme creates energy with the stepping loads, not on its own.
  double load_step_dissipation = 0;
  // Coupled runs: the work of the coupler's loads as the coupler books it, sum over windows of
  // F_w . v(window start) * window size (J; 2D: the coupler's J/m times the strip depth). The
  // solid's own external_work books F_w . (x_end - x_start); the two differ by the explicit
  // coupling's interface energy error (docs/solid_fe.md, "Energy in coupled runs").
  double interface_work = 0;
  double initial_kinetic = 0;
  // Largest energy term seen so far in the run (J): the scale of the energy-growth stop.
  double largest_energy = 0;
  // KE + W_int + W_damp + W_contact + W_tie - W_ext - KE0: zero for exact time integration.
  double balance() const {
    return kinetic + internal_work + damping_work + contact_work + tie_work + numerical_dissipation - external_work -
           initial_kinetic;
  }
  // |balance| relative to the largest energy term now.
  double relative_balance_error() const;
  // |balance| relative to the largest energy term seen in the run (largest_energy).
  double balance_error_of_largest() const;
  // Raises largest_energy to the largest energy term now.
  void update_largest_energy();
};

struct SolverState {
  double time = 0;
  std::int64_t step = 0;
  Eigen::Matrix3Xd position;           // x at `time`
  Eigen::Matrix3Xd half_step_velocity; // v at time - dt/2
  Eigen::Matrix3Xd velocity;           // v at `time` (for output and kinetic energy)
  Eigen::Matrix3Xd internal_force;     // at `position` (hourglass included)
  Eigen::Matrix3Xd hourglass_force;    // its hourglass part (bricks; empty for shells)
  Eigen::Matrix3Xd external_force;     // at `position`, last evaluated
  Eigen::Matrix3Xd contact_force;      // at `position`
  Eigen::Matrix3Xd tie_force;          // coaptation tie springs at `position` (empty without a tie)
  std::int64_t nodes_in_contact = 0;
  double last_step = 0;                // dt of the last step
  // The last step before it was cut to land on a window's or an output's end. The growth limit
  // starts from it: started from the cut step it ratcheted the step down window after window
  // (coupled 2D valve: 0.04 us steps where 1 us was stable, 57 steps per 6.5 us window).
  double uncut_step = 0;
  double stable_step = 0;              // current stable step estimate (safety applied)
  // The look-ahead's bound lay > 10 % below the present one at the last estimate: the mesh is
  // running into stiffer states, and the step is re-estimated at every step until it is not.
  bool stiffening_ahead = false;
  std::int64_t critical_element = -1;  // element that sets stable_step
  EnergyBalance energy;
  // Stable-step calibration (Lanczos on M^-1 K): critical step used / element estimate.
  double step_calibration = 1.0;
  double highest_frequency = 0;        // omega_max of the last calibration (rad/s)
  double calibrated_step = 0;          // 2 / omega_max at the last calibration (s)
  double element_step_at_calibration = 0;
  std::int64_t calibrated_at_step = -1;
  int calibration_iterations = 0;      // Lanczos steps of the last calibration
  Eigen::Matrix3Xd power_vector;       // last eigenvector estimate
  // Contact: omega^2 fixing the penalty stiffness (set at the first step, then constant) and the
  // leaflet-leaflet candidate pairs (their order sets the order of the force sums).
  double contact_omega2 = 0.0;
  ContactCandidates contact_candidates;
  CoaptationTieState tie;
  // Implicit dynamics: the acceleration at `time` (empty until the first implicit step), the step
  // proposed for the next one and the Newton iterations of the last one.
  Eigen::Matrix3Xd acceleration;
  double implicit_step = 0;
  int newton_iterations = 0;
  // Automatic switch: the implicit integrator is stepping; since when the model has been settled
  // (s; < 0: it is not); the pressure when implicit began (Pa); switches so far.
  bool implicit_phase = false;
  double settled_since = -1;
  double implicit_switch_pressure = 0;
  std::int64_t switches = 0;
  // Automatic switch with settled_filter_time > 0: the velocity low-pass filtered with that time
  // constant (empty until the first step) and its kinetic energy, which the switch to implicit
  // reads; in the implicit phase, whether the instantaneous kinetic energy has fallen to
  // moving_kinetic_ratio x strain energy since the switch (from then on it rising above again
  // means motion, before that it is the chatter the explicit phase left).
  Eigen::Matrix3Xd slow_velocity;
  double slow_kinetic = 0;
  bool chatter_damped = false;
  // Automatic switch's cost rule (implicit_tangent_cost > 0): the explicit step when the implicit
  // phase began (s; 0: unknown, the rule waits for the next switch); the implicit phase's steps,
  // its current block's work in explicit-step equivalents, the block's start time and the step
  // proposed then; how often
  // the rule has sent the run back to explicit.
  double explicit_step_at_switch = 0;
  std::int64_t phase_steps = 0;
  double block_work = 0;
  double block_start = 0;
  double block_start_step = 0;
  std::int64_t cost_switches = 0;
};

struct SymmetryConstraint {
  std::int64_t node;
  Eigen::Vector3d normal;  // the node keeps zero displacement along this unit normal
};

// Rigid cylinder (stent): nodes keep their distance from the axis at most radius - t/2.
struct ContactCylinder {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // a point on the axis
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();   // unit direction
  double radius = 0;
};

// A front/back node pair of a plane-strain strip (2D runs): both move alike in x-y.
struct StripTie {
  std::int64_t front;
  std::int64_t back;
};

enum class TimeIntegration {
  explicit_central_difference,  // the default: lumped-mass central difference, stable-step bound
  implicit_generalized_alpha,   // Newton on each step, adaptive step (implicit_dynamics.cpp)
  // Explicit while the leaflets move, implicit once they have settled (kinetic energy a small
  // fraction of the strain energy for a while), explicit again when the load reverses or the
  // motion returns (docs/solid_fe.md, "Automatic switch").
  automatic,
};

struct SolverOptions {
  double contact_stiffness_factor = 0.1;  // penalty k = factor * m * omega_max^2 per node
  // Leaflet-leaflet pairs in contact: a normal dashpot at this fraction of the critical damping
  // of the pair's penalty spring (2 sqrt(k m_pair)), on the closing speed; 0 = none. Explicit
  // steps read the half-step velocity v(n - 1/2), implicit ones the trial velocity. Case field
  // solid.leaflet_contact_damping_ratio (docs/solid_fe.md, "Sixteenth session").
  double contact_damping_ratio = 0.0;
  double time_step_safety = 0.8;        // fraction of the estimated critical step
  double mass_damping_per_s = 0.0;      // alpha of the damping force alpha m v (off when 0)
  // > 0: alpha while the pressure waveform is negative (the valve loaded closed), in place of
  // mass_damping_per_s; no waveform (coupled runs): unused. Case field
  // solid.diastolic_mass_damping_per_s (docs/solid_fe.md, "Sixteenth session (b)").
  double diastolic_mass_damping_per_s = 0.0;
  // Back pressure (Pa, >= 0) beyond which the diastolic damping acts: it applies while the waveform
  // is below -diastolic_damping_onset_Pa. Case field solid.diastolic_damping_onset_mmHg.
  double diastolic_damping_onset_Pa = 0.0;
  int time_step_update_interval = 10;   // re-estimate the stable step every this many steps
  double max_time_step = 1e-4;          // upper bound on dt (s)
  // Every this many steps (or when the element estimate falls below 70 % of its value then) the
  // model's highest frequency is found by Lanczos (finite-difference K v) and the step set from
  // it; 0 = element estimate only.
  int time_step_calibration_interval = 0;
  int power_iterations = 30;            // Lanczos steps at most per calibration (stops when converged)
  double max_step_calibration = 1.5;     // the calibrated step is at most this times the element estimate
  double max_time_step_growth = 0;       // > 0: dt grows by at most this fraction per step
  double fixed_time_step = 0;           // > 0: this step, no estimate (tests of the stability limit)
  // > 0: the element estimate is also taken at the state the current velocities reach after this
  // many steps (x + v * look_ahead * dt) and the smaller one used: an element stiffening fast
  // (MHGO's exponential near a whipping free corner) is resolved before it is met.
  double time_step_look_ahead = 0;
  // > 0: stop (EnergyGrowthError) when |balance| exceeds this fraction of the largest energy
  // seen, checked every step from step kEnergyCheckFirstStep on; 0 = off.
  double max_energy_balance_error = 0;
  // Implicit dynamics (docs/solid_fe.md, "Implicit dynamics"): generalized-alpha (Chung & Hulbert
  // 1993) with spectral radius rho_inf at infinite frequency (1 = average acceleration, no
  // dissipation; 0 = asymptotic annihilation); Newton converges when the residual's norm is below
  // newton_tolerance x the largest of the inertia, internal and external forces' norms.
  TimeIntegration time_integration = TimeIntegration::explicit_central_difference;
  double spectral_radius_infinity = 0.8;
  double implicit_initial_step = 1e-6;  // first step (s)
  double implicit_min_step = 1e-10;     // a step cut below this stops the run (NewtonFailureError)
  double newton_tolerance = 1e-6;
  int newton_max_iterations = 10;
  int newton_fast_iterations = 4;       // converged within this many twice in a row: the step doubles
  // Automatic switch: implicit once kinetic <= settled_kinetic_ratio x strain energy has held for
  // settled_hold (s); explicit again when the pressure changes sign or kinetic > moving_kinetic_ratio
  // x strain energy (with settled_filter_time > 0, below).
  double settled_kinetic_ratio = 0.05;
  double settled_hold = 5e-3;
  double moving_kinetic_ratio = 0.1;
  // > 0: the switch to implicit compares the kinetic energy of the velocity low-pass filtered
  // with this time constant (s), so that vibration much faster than it (the closed leaflet's
  // ~7 kHz ringing, a pressed flap's contact chatter) does not count as motion. Back to explicit
  // when that filtered energy exceeds moving_kinetic_ratio x strain energy, or the instantaneous
  // one does after it has once fallen below (the implicit scheme first damps the inherited
  // vibration; a release is then caught as fast as without the filter). 0: the instantaneous
  // kinetic energy throughout (docs/solid_fe.md, "Automatic switch"). Off by default: it pays
  // only with a dissipative scheme (spectral_radius_infinity 0.5: the coarse sector's cycle 171 ->
  // 45 s CPU); with 0.8 the implicit open phase it starts crawls at ~1-3 us steps.
  // Case field: solid.settled_filter_time_s.
  double settled_filter_time = 0;
  // > 0: the automatic switch's cost rule, with this the cost of building and factorising the
  // implicit tangent in explicit steps (a Newton iteration's force evaluation counts 1, as an
  // explicit step). Each block of kCostRuleSteps implicit steps after the phase's first (the
  // step's ramp from implicit_initial_step) books its work; when it exceeds the explicit steps
  // the block's time would have taken at the phase's starting explicit step and the step did not
  // grow over the block, the run goes back to explicit (the next switch to implicit waits for
  // settled_hold again). 0: off. Case field
  // solid.implicit_tangent_cost (docs/solid_fe.md, "Fourteenth session").
  double implicit_tangent_cost = 0;
};

// Cost rule's block of implicit steps: the phase's first block is its step's ramp (doubling every
// two fast steps from implicit_initial_step: 2^8-fold in 16 steps) and is not judged.
inline constexpr std::int64_t kCostRuleSteps = 16;
// The energy-growth check starts here: the first steps' balance is a ratio of round-off-sized
// energies.
inline constexpr std::int64_t kEnergyCheckFirstStep = 100;
// The energy-growth check's scale is at least the model's strain energy at this strain (a
// volume-preserving stretch): ledgers of a model that has barely moved hold round-off-sized
// energies (docs/solid_fe.md, "Energy-growth stop").
inline constexpr double kEnergyFloorStrain = 1e-3;
// AUTOMATIC's implicit steps change the pressure by at most this fraction of the larger of the
// pressure now and at the switch: a release is followed in steps, not jumped over (a 1 ms step
// across the pressed flap's 1 ms release damped its spring-back: 0.1 mm off at 75 ms).
inline constexpr double kAutomaticLoadChangePerStep = 0.01;

class ExplicitSolver {
 public:
  ExplicitSolver(std::unique_ptr<ElementModel> elements, SolverOptions options = {});
  virtual ~ExplicitSolver() = default;
  ExplicitSolver(const ExplicitSolver&) = delete;
  ExplicitSolver& operator=(const ExplicitSolver&) = delete;

  // Uniform transvalvular pressure dp(t) (Pa) on the element model's loaded surface.
  void set_pressure_waveform(std::function<double(double)> pressure_Pa);
  void add_symmetry_constraints(const std::vector<SymmetryConstraint>& constraints);
  // Rigid plane the leaflet surface (mid-surface offset by t/2 for shells) may touch but not
  // cross; the plane's normal points to the side where the leaflet lives. Penalty on nodes.
  void add_contact_plane(const Plane& plane);
  // Leaflet-leaflet contact between nodes and triangles of different surfaces (ids per node;
  // empty: any non-incident triangle), and with self_contact also within a surface beyond the
  // neighbours along it (leaflet_contact.hpp). Shell elements only (throws std::invalid_argument).
  void enable_leaflet_contact(std::vector<int> surface_of_node, bool self_contact = false);
  // Stent: penalty contact keeping every free node inside the cylinder by half its thickness.
  void add_contact_cylinder(const ContactCylinder& cylinder);
  // Plane-strain strip (2D runs): u_z = 0 on every node and each pair moves alike in x-y
  // (mass-weighted, so momentum and the energy balance hold).
  void set_strip_ties(std::vector<StripTie> ties);
  const std::vector<StripTie>& strip_ties() const { return ties_; }
  // Coaptation tie (coaptation_tie.hpp): its plane must be one of the contact planes added.
  // Throws std::invalid_argument for an unknown plane, node or a non-positive release force.
  void set_coaptation_tie(CoaptationTie tie);
  const std::optional<CoaptationTie>& coaptation_tie() const { return tie_; }
  const LeafletContact* leaflet_contact() const { return leaflet_contact_ ? &*leaflet_contact_ : nullptr; }
  void set_velocity(const Eigen::Matrix3Xd& velocity);  // initial condition (before the first step)

  // Advances to exactly t_end under `nodal_forces` (3 x nodes, N; constant over the window)
  // added to the pressure load. Throws MaterialStateError naming the element, time and step.
  void advance_window(double t_end, const Eigen::Matrix3Xd* nodal_forces = nullptr);
  // The step now is implicit (IMPLICIT, or AUTOMATIC in its implicit phase).
  bool implicit() const {
    return options_.time_integration == TimeIntegration::implicit_generalized_alpha ||
           (automatic() && state_.implicit_phase);
  }
  bool automatic() const { return options_.time_integration == TimeIntegration::automatic; }
  // Restart points: the next implicit step builds its tangent afresh, as a run continued from the
  // restart file does (the kept factorisation is not in the file), so both continue bit for bit.
  void drop_kept_tangent();

  const SolverState& state() const { return state_; }
  // The energy-growth check's smallest scale (J): the strain energy at kEnergyFloorStrain.
  double energy_check_floor() const { return energy_check_floor_; }
  // What the energy-growth stop compares with solver.max_energy_balance_error: max(|balance|,
  // energy the implicit scheme created beyond the loads' window steps) over the largest energy
  // seen, at least the model's floor. The progress lines print it.
  double energy_growth_measure() const;
  void restore(const SolverState& saved) {
    state_ = saved;
    internal_force_current_ = true;
  }
  const ElementModel& elements() const { return *elements_; }
  const SolverOptions& options() const { return options_; }
  // The mass-proportional damping alpha (1/s) of a step starting at t: diastolic_mass_damping_per_s
  // when that is > 0 and the pressure waveform is below -diastolic_damping_onset_Pa at t, else
  // mass_damping_per_s.
  double mass_damping_at(double t) const;
  Eigen::Matrix3Xd displacement() const { return state_.position - elements_->reference_positions(); }

  // Per-element maximum principal Cauchy stress (Pa) and logarithmic strain of the state.
  void element_fields(Eigen::VectorXd& max_principal_stress, Eigen::VectorXd& max_principal_log_strain) const {
    elements_->element_fields(state_.position, max_principal_stress, max_principal_log_strain);
  }

  // Diagnostics: called with the state after every completed step (empty: none).
  void set_step_observer(std::function<void(const SolverState&)> observer) { step_observer_ = std::move(observer); }

  // For tests: the next estimates use dt = factor x the critical-step estimate (safety ignored).
  void set_step_factor_for_testing(double factor) { step_factor_ = factor; }

 protected:
  ElementModel& mutable_elements() { return *elements_; }
  void invalidate_forces() { internal_force_current_ = false; }

 private:
  void compute_internal_force(bool estimate_step);
  // Internal force at x into `out`; returns the element result (energies, step bound).
  InternalForceResult evaluate_internal_force(const Eigen::Matrix3Xd& x, bool estimate_step, Eigen::Matrix3Xd& out,
                                              Eigen::Matrix3Xd* hourglass);
  // Lanczos for omega_max of M^-1 K at the current state; sets the calibration fields of the state.
  void calibrate_stable_step(double element_step);
  void compute_external_force(double t, const Eigen::Matrix3Xd* nodal_forces);
  void compute_contact_force();
  // Catches touching tip groups, releases over-pulled ones, and sets state_.tie_force.
  void update_coaptation_tie(double stiffness_per_mass);
  // (external + contact + tie - internal) / m with the constraints applied, into acceleration_.
  void compute_acceleration(const Eigen::ArrayXd& inverse_mass);
  void apply_constraints(Eigen::Matrix3Xd& field) const;
  void update_kinetic_energy();
  // Throws EnergyGrowthError when the balance error passes options_.max_energy_balance_error.
  void check_energy_growth() const;
  double model_energy_floor();
  void add_work(const Eigen::Matrix3Xd& dx);
  // Implicit dynamics (implicit_dynamics.cpp): the window loop, one step of size h from the
  // present state (false when Newton did not converge; the state is then unchanged), and the
  // per-node constraint projectors.
  void advance_window_implicit(double t_end, const Eigen::Matrix3Xd* nodal_forces);
  bool implicit_step(double h, const Eigen::Matrix3Xd* nodal_forces, double& residual, Eigen::Index& worst_node);
  void prepare_implicit();
  // Builds and factorises the step's tangent at the present trial state (false if it cannot).
  bool factorise_tangent(double h, double t_new, double mass_coefficient, double stiffness_coefficient);
  // The present Newton iterate's plane and stent contact set (true: it changed since the last
  // iterate of the step), and the low-rank update that gives a kept factorisation that set's
  // springs: prepared (false: too many changed springs or singular; refactorise) and applied to
  // a solve's result.
  bool update_iterate_contact_set(bool first_iterate);
  bool prepare_spring_update(double stiffness_coefficient);
  bool apply_spring_update(Eigen::VectorXd& solved) const;
  // Books a converged step from `start` (velocity, acceleration, energies).
  bool finish_implicit_step(const SolverState& start, double h);
  // Automatic switch's cost rule (options_.implicit_tangent_cost): books an accepted implicit
  // step's work and says, at the end of a block, whether explicit steps would have been cheaper;
  // start_cost_rule begins a phase's books at the switch to implicit.
  bool implicit_costs_more();
  void start_cost_rule();
  // Automatic switch: the tests after an explicit step (to implicit) and an implicit one (back).
  bool settled_for_implicit();
  // After a step of h: low-pass filters the velocity (settled_filter_time > 0).
  void update_slow_velocity(double h);
  bool moving_again();
  void switch_to_explicit();
  int pressure_sign(double t) const;
  bool has_contact() const { return !contact_planes_.empty() || !contact_cylinders_.empty() || leaflet_contact_; }

  std::unique_ptr<ElementModel> elements_;
  SolverOptions options_;
  std::function<double(double)> pressure_;
  std::vector<SymmetryConstraint> symmetry_;
  std::vector<Plane> contact_planes_;
  std::vector<ContactCylinder> contact_cylinders_;
  std::vector<StripTie> ties_;
  bool planar_ = false;  // u_z = 0 everywhere (strip mode)
  std::optional<LeafletContact> leaflet_contact_;
  std::optional<CoaptationTie> tie_;
  std::size_t tie_plane_ = 0;           // index of the tie's plane in contact_planes_
  std::vector<std::uint8_t> tie_held_;  // per node: held by a tie now (the tie's plane skips it)
  double step_factor_ = 0.0;     // > 0: tests' override of the safety factor
  std::function<void(const SolverState&)> step_observer_;
  Eigen::VectorXd half_thickness_;  // per node: contact offset of the surface
  Eigen::Matrix3Xd own_contact_force_;  // implicit with leaflet contact: the planes' and stent's part
  Eigen::Matrix3Xd acceleration_;
  Eigen::Matrix3Xd previous_half_velocity_;  // for the damping work
  Eigen::Matrix3Xd probe_position_, probe_force_, probe_vector_;  // calibration work arrays
  std::vector<Eigen::Matrix3Xd> lanczos_basis_;
  Eigen::Matrix3Xd step_increment_;
  struct ImplicitWork;  // sparse matrices, factorisation and work arrays of implicit dynamics
  std::shared_ptr<ImplicitWork> implicit_;
  bool internal_force_current_ = false;
  double energy_check_floor_ = 0;  // J (model_energy_floor)
  SolverState state_;
};

}  // namespace valvefsi::solid
