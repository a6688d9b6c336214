#include "valvefsi/solid/explicit_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "valvefsi/solid/energy_growth_error.hpp"
#include "valvefsi/solid/material_error.hpp"

namespace valvefsi::solid {
double EnergyBalance::relative_balance_error() const {
  const double scale = std::max({std::abs(kinetic), std::abs(internal_work), std::abs(external_work),
                                 std::abs(damping_work), std::abs(contact_work), std::abs(tie_work),
                                 std::abs(initial_kinetic),
                                 1e-300});
  return std::abs(balance()) / scale;
}

void EnergyBalance::update_largest_energy() {
  largest_energy = std::max({largest_energy, std::abs(kinetic), std::abs(internal_work), std::abs(strain_energy),
                             std::abs(external_work), std::abs(damping_work), std::abs(contact_work),
                             std::abs(tie_work), std::abs(initial_kinetic)});
}

double EnergyBalance::balance_error_of_largest() const {
  return std::abs(balance()) / std::max(largest_energy, 1e-300);
}

ExplicitSolver::ExplicitSolver(std::unique_ptr<ElementModel> elements, SolverOptions options)
    : elements_(std::move(elements)), options_(options) {
  if (!elements_) throw std::invalid_argument("solid: no element model");
  if (!(options_.time_step_safety > 0.0 && options_.time_step_safety <= 1.0)) {
    throw std::invalid_argument(fmt::format(
        "solid: time_step_safety = {}: allowed (0, 1]", options_.time_step_safety));
  }
  if (!(options_.contact_damping_ratio >= 0.0 && options_.contact_damping_ratio <= 1.0)) {
    throw std::invalid_argument(fmt::format(
        "solid: contact_damping_ratio = {}: allowed [0, 1]", options_.contact_damping_ratio));
  }
  if (options_.time_step_update_interval < 1) {
    throw std::invalid_argument(fmt::format(
        "solid: time_step_update_interval = {}: allowed >= 1", options_.time_step_update_interval));
  }
  const Eigen::Index n = elements_->reference_positions().cols();
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!(elements_->nodal_mass()(i) > 0.0)) {
      throw std::invalid_argument(fmt::format("solid: node {} belongs to no {} element (zero mass)", i,
                                              elements_->family()));
    }
  }
  state_.position = elements_->reference_positions();
  for (Eigen::Matrix3Xd* m : {&state_.half_step_velocity, &state_.velocity, &state_.internal_force,
                              &state_.external_force, &state_.contact_force, &acceleration_}) {
    *m = Eigen::Matrix3Xd::Zero(3, n);
  }
  if (elements_->has_hourglass_forces()) state_.hourglass_force = Eigen::Matrix3Xd::Zero(3, n);
  half_thickness_ = elements_->contact_half_thickness();
  energy_check_floor_ = model_energy_floor();
}

double ExplicitSolver::model_energy_floor() {
  // The strain energy of the whole model under a volume-preserving stretch of kEnergyFloorStrain
  // along x (a shell in any orientation is strained by it, bricks are not loaded through their
  // bulk modulus): the energy scale of "the model has barely moved", from its own size, thickness
  // and stiffness, so the same rule holds for a 2D strip, a sector and a test plate.
  const Eigen::Matrix3Xd& reference = elements_->reference_positions();
  const Eigen::Vector3d centre = reference.rowwise().mean();
  const Eigen::Vector3d stretch(1.0 + kEnergyFloorStrain, 1.0 / std::sqrt(1.0 + kEnergyFloorStrain),
                                1.0 / std::sqrt(1.0 + kEnergyFloorStrain));
  const Eigen::Matrix3Xd stretched = (stretch.asDiagonal() * (reference.colwise() - centre)).colwise() + centre;
  Eigen::Matrix3Xd forces(3, reference.cols());
  return elements_->internal_force(stretched, false, forces, nullptr).strain_energy;
}

void ExplicitSolver::set_pressure_waveform(std::function<double(double)> pressure_Pa) {
  pressure_ = std::move(pressure_Pa);
  internal_force_current_ = false;
}

void ExplicitSolver::add_symmetry_constraints(const std::vector<SymmetryConstraint>& constraints) {
  for (const auto& c : constraints) symmetry_.push_back({c.node, c.normal.normalized()});
}

void ExplicitSolver::add_contact_plane(const Plane& plane) {
  contact_planes_.push_back({plane.point, plane.normal.normalized()});
  internal_force_current_ = false;
}

void ExplicitSolver::enable_leaflet_contact(std::vector<int> surface_of_node, bool self_contact) {
  const ShellModel* surface = elements_->contact_surface();
  if (surface == nullptr) {
    throw std::invalid_argument(fmt::format("solid: leaflet-leaflet contact needs shell elements, not {}",
                                            elements_->family()));
  }
  leaflet_contact_.emplace(*surface, std::move(surface_of_node), self_contact);
  internal_force_current_ = false;
}

void ExplicitSolver::add_contact_cylinder(const ContactCylinder& cylinder) {
  if (!(cylinder.radius > 0.0) || !(cylinder.axis.norm() > 0.0)) {
    throw std::invalid_argument(fmt::format("solid: contact cylinder radius {} m, axis norm {}: allowed > 0",
                                            cylinder.radius, cylinder.axis.norm()));
  }
  contact_cylinders_.push_back({cylinder.origin, cylinder.axis.normalized(), cylinder.radius});
  internal_force_current_ = false;
}

void ExplicitSolver::set_strip_ties(std::vector<StripTie> ties) {
  const Eigen::Index n = elements_->reference_positions().cols();
  for (const auto& t : ties) {
    if (t.front < 0 || t.front >= n || t.back < 0 || t.back >= n || t.front == t.back) {
      throw std::invalid_argument(fmt::format("solid: strip tie ({}, {}): nodes must differ and exist (mesh has {})",
                                              t.front, t.back, n));
    }
  }
  ties_ = std::move(ties);
  planar_ = true;
  apply_constraints(state_.velocity);
  apply_constraints(state_.half_step_velocity);
  internal_force_current_ = false;
}

void ExplicitSolver::set_coaptation_tie(CoaptationTie tie) {
  tie.plane.normal.normalize();
  std::size_t index = contact_planes_.size();
  for (std::size_t k = 0; k < contact_planes_.size(); ++k) {
    if ((contact_planes_[k].point - tie.plane.point).norm() <= 1e-12 * (1.0 + tie.plane.point.norm()) &&
        (contact_planes_[k].normal - tie.plane.normal).norm() <= 1e-12) {
      index = k;
    }
  }
  if (index == contact_planes_.size()) {
    throw std::invalid_argument("solid: coaptation tie: its plane is not one of the solver's contact planes");
  }
  if (!(tie.release_force > 0.0)) {
    throw std::invalid_argument(fmt::format("solid: coaptation tie release force {} N: allowed > 0", tie.release_force));
  }
  const Eigen::Index n = elements_->reference_positions().cols();
  Eigen::Index count = 0;
  for (const auto& group : tie.groups) {
    if (group.empty()) throw std::invalid_argument("solid: coaptation tie: an empty node group");
    for (const std::int64_t node : group) {
      if (node < 0 || node >= n || elements_->fixed()[static_cast<std::size_t>(node)]) {
        throw std::invalid_argument(fmt::format(
            "solid: coaptation tie node {}: allowed a free node of the mesh (0 to {})", node, n - 1));
      }
      ++count;
    }
  }
  tie_plane_ = index;
  state_.tie = CoaptationTieState{};
  state_.tie.tied.assign(tie.groups.size(), 0);
  state_.tie.anchor = Eigen::Matrix3Xd::Zero(3, count);
  state_.tie_force = Eigen::Matrix3Xd::Zero(3, n);
  tie_held_.assign(static_cast<std::size_t>(n), 0);
  tie_ = std::move(tie);
  internal_force_current_ = false;
}

void ExplicitSolver::update_coaptation_tie(double stiffness_per_mass) {
  // A group is caught when its mean gap to the plane's contact surface is <= 0 (it touches),
  // anchored at the touching points, so the spring force equals the plane's penalty force at
  // that moment; it is released when the summed spring force pulls towards -normal (the tips
  // try to leave the plane) harder than the release force. One spring per node, the stiffness
  // of the contact penalty: -k (x - anchor) in every direction.
  const Plane& plane = contact_planes_[tie_plane_];
  const Eigen::Matrix3Xd& x = state_.position;
  const Eigen::VectorXd& mass = elements_->nodal_mass();
  CoaptationTieState& tie = state_.tie;
  Eigen::Matrix3Xd& f = state_.tie_force;
  f.setZero();
  std::fill(tie_held_.begin(), tie_held_.end(), 0);
  double stored = 0.0;
  Eigen::Index column = 0;
  for (std::size_t g = 0; g < tie_->groups.size(); ++g) {
    const auto& group = tie_->groups[g];
    const auto first = column;
    column += static_cast<Eigen::Index>(group.size());
    if (tie.tied[g]) {
      Eigen::Vector3d total = Eigen::Vector3d::Zero();
      for (std::size_t j = 0; j < group.size(); ++j) {
        const auto i = group[j];
        total -= stiffness_per_mass * mass(i) * (x.col(i) - tie.anchor.col(first + static_cast<Eigen::Index>(j)));
      }
      if (total.dot(plane.normal) < 0.0) {
        tie.peak_force = std::max(tie.peak_force, total.norm());
        if (total.norm() > tie_->release_force) {
          tie.tied[g] = 0;
          ++tie.releases;
        }
      }
    } else {
      double mean_gap = 0.0;
      for (const auto i : group) mean_gap += (x.col(i) - plane.point).dot(plane.normal) - half_thickness_(i);
      if (mean_gap <= 0.0) {
        tie.tied[g] = 1;
        ++tie.captures;
        for (std::size_t j = 0; j < group.size(); ++j) {
          const auto i = group[j];
          const double gap = (x.col(i) - plane.point).dot(plane.normal) - half_thickness_(i);
          tie.anchor.col(first + static_cast<Eigen::Index>(j)) = x.col(i) - gap * plane.normal;
        }
      }
    }
    if (!tie.tied[g]) continue;
    for (std::size_t j = 0; j < group.size(); ++j) {
      const auto i = group[j];
      const Eigen::Vector3d stretch = x.col(i) - tie.anchor.col(first + static_cast<Eigen::Index>(j));
      const double k = stiffness_per_mass * mass(i);
      f.col(i) -= k * stretch;
      stored += 0.5 * k * stretch.squaredNorm();
      tie_held_[static_cast<std::size_t>(i)] = 1;
    }
  }
  state_.energy.tie_energy = stored;
}

void ExplicitSolver::compute_acceleration(const Eigen::ArrayXd& inverse_mass) {
  Eigen::Matrix3Xd& a = acceleration_;
  a = state_.external_force + state_.contact_force - state_.internal_force;
  if (tie_) a += state_.tie_force;
  a.array().rowwise() *= inverse_mass.transpose();
  apply_constraints(a);
}

void ExplicitSolver::compute_contact_force() {
  Eigen::Matrix3Xd& f = state_.contact_force;
  f.setZero();
  state_.nodes_in_contact = 0;
  if (!has_contact()) return;
  // Penalty stiffness from the highest frequency the first step resolves, k = factor m (2/dt)^2,
  // then kept: a constant spring is conservative, and the step only shrinks as tissue stiffens.
  if (state_.contact_omega2 == 0.0) {
    const double dt_critical =
        state_.stable_step / (step_factor_ > 0.0 ? step_factor_ : options_.time_step_safety);
    state_.contact_omega2 = 4.0 / (dt_critical * dt_critical);
  }
  const double omega2 = state_.contact_omega2;
  const Eigen::Matrix3Xd& x = state_.position;
  const auto& fixed = elements_->fixed();
  const Eigen::VectorXd& mass = elements_->nodal_mass();
  if (tie_) update_coaptation_tie(options_.contact_stiffness_factor * omega2);
  for (std::size_t p = 0; p < contact_planes_.size(); ++p) {
    const Plane& plane = contact_planes_[p];
    const bool tie_plane = tie_ && p == tie_plane_;
    for (Eigen::Index i = 0; i < x.cols(); ++i) {
      if (tie_plane && tie_held_[static_cast<std::size_t>(i)]) continue;  // the tie holds it both ways
      const double gap = (x.col(i) - plane.point).dot(plane.normal) - half_thickness_(i);
      if (gap < 0.0 && !fixed[static_cast<std::size_t>(i)]) {
        f.col(i) -= options_.contact_stiffness_factor * mass(i) * omega2 * gap * plane.normal;
        ++state_.nodes_in_contact;
      }
    }
  }
  for (const ContactCylinder& cylinder : contact_cylinders_) {
    for (Eigen::Index i = 0; i < x.cols(); ++i) {
      if (fixed[static_cast<std::size_t>(i)]) continue;
      const Eigen::Vector3d d = x.col(i) - cylinder.origin;
      const Eigen::Vector3d radial = d - d.dot(cylinder.axis) * cylinder.axis;
      const double r = radial.norm();
      const double penetration = r + half_thickness_(i) - cylinder.radius;
      if (penetration > 0.0 && r > 0.0) {
        f.col(i) -= options_.contact_stiffness_factor * mass(i) * omega2 * penetration * (radial / r);
        ++state_.nodes_in_contact;
      }
    }
  }
  if (leaflet_contact_) {
    if (implicit_) own_contact_force_ = f;  // the tangent's per-node springs (implicit_dynamics.cpp)
    // The pairs' dashpots read the velocity of the step the forces belong to: explicit steps the
    // half-step velocity v(n - 1/2) (lagged, as explicit codes take their contact damping),
    // Newton's iterations the trial velocity (implicit_step sets it there).
    state_.nodes_in_contact += leaflet_contact_->add_forces(
        *elements_->contact_surface(), x, options_.contact_stiffness_factor * omega2, f, state_.contact_candidates,
        &state_.half_step_velocity, options_.contact_damping_ratio);
  }
}

void ExplicitSolver::set_velocity(const Eigen::Matrix3Xd& velocity) {
  state_.velocity = velocity;
  state_.half_step_velocity = velocity;
  apply_constraints(state_.velocity);
  apply_constraints(state_.half_step_velocity);
  internal_force_current_ = false;
}

void ExplicitSolver::apply_constraints(Eigen::Matrix3Xd& field) const {
  if (planar_) {
    field.row(2).setZero();
    for (const auto& t : ties_) {
      const double ma = elements_->nodal_mass()(t.front), mb = elements_->nodal_mass()(t.back);
      const Eigen::Vector3d mean = (ma * field.col(t.front) + mb * field.col(t.back)) / (ma + mb);
      field.col(t.front) = mean;
      field.col(t.back) = mean;
    }
  }
  for (const auto& c : symmetry_) {
    auto col = field.col(c.node);
    col -= col.dot(c.normal) * c.normal;
  }
  const auto& fixed = elements_->fixed();
  for (std::size_t i = 0; i < fixed.size(); ++i) {
    if (fixed[i]) field.col(static_cast<Eigen::Index>(i)).setZero();
  }
}

InternalForceResult ExplicitSolver::evaluate_internal_force(const Eigen::Matrix3Xd& x, bool estimate_step,
                                                             Eigen::Matrix3Xd& out, Eigen::Matrix3Xd* hourglass) {
  try {
    return elements_->internal_force(x, estimate_step, out, hourglass);
  } catch (const MaterialStateError& ex) {
    throw MaterialStateError(fmt::format("solid at t = {:.6g} s, step {}: {}", state_.time, state_.step, ex.what()));
  }
}

void ExplicitSolver::compute_internal_force(bool estimate_step) {
  const InternalForceResult r =
      evaluate_internal_force(state_.position, estimate_step, state_.internal_force,
                              elements_->has_hourglass_forces() ? &state_.hourglass_force : nullptr);
  state_.energy.strain_energy = r.strain_energy;
  state_.energy.hourglass_energy = r.hourglass_energy;
  const double bound_now = r.min_step;  // the element bound of the present state
  double min_step = r.min_step;
  std::int64_t critical = r.critical_element;
  if (estimate_step && options_.fixed_time_step <= 0.0 && options_.time_step_look_ahead > 0.0 && state_.last_step > 0.0) {
    // The element bound where the present motion leads within the look-ahead; a state the
    // material cannot evaluate (overflow) is approached by halving the look-ahead.
    state_.stiffening_ahead = false;
    double span = options_.time_step_look_ahead * state_.last_step;
    for (int attempt = 0; attempt < 4; ++attempt, span *= 0.5) {
      probe_position_ = state_.position + span * state_.half_step_velocity;
      try {
        const InternalForceResult ahead = elements_->internal_force(probe_position_, true, probe_force_, nullptr);
        state_.stiffening_ahead = ahead.min_step < 0.9 * bound_now;
        if (ahead.min_step < min_step) {
          min_step = ahead.min_step;
          critical = ahead.critical_element;
        }
        break;
      } catch (const MaterialStateError&) {
      }
    }
  }
  if (options_.fixed_time_step > 0.0) {
    state_.stable_step = options_.fixed_time_step;
  } else if (estimate_step) {
    // Element estimate (usually below the true critical step), or, when calibrating, the
    // model's own critical step 2/omega_max from the last Lanczos run, scaled down (never up)
    // by how much the element estimate fell since then, so stiffening between calibrations
    // is followed; a fall below 70 % triggers a new calibration.
    double critical_step = min_step;
    const int interval = options_.time_step_calibration_interval;
    if (interval > 0) {
      // (Calibrations follow the present state's bound: a dip of the look-ahead bound alone
      // scales the step down below but does not start a Lanczos run.)
      const bool due = state_.calibrated_at_step < 0 || state_.step - state_.calibrated_at_step >= interval ||
                       bound_now < 0.7 * state_.element_step_at_calibration;
      if (due) calibrate_stable_step(bound_now);
      if (state_.calibrated_step > 0.0) {
        // Below the element estimate too: the element bound is not always below the model's
        // (pressed MHGO flap: 15.1 us against 2/omega_max = 13.7 us).
        critical_step = std::min(
            state_.calibrated_step * std::min(1.0, min_step / state_.element_step_at_calibration),
            options_.max_step_calibration * min_step);
      }
      state_.step_calibration = critical_step / min_step;
    }
    const double safety = step_factor_ > 0.0 ? step_factor_ : options_.time_step_safety;
    state_.stable_step = std::min(safety * critical_step, options_.max_time_step);
    state_.critical_element = critical;
  }
  internal_force_current_ = true;
}

void ExplicitSolver::calibrate_stable_step(double element_step) {
  // Lanczos on M^-1 K in the mass inner product (symmetric there), K q by a forward difference
  // of the internal force, full re-orthogonalisation (few vectors). The largest Ritz value plus
  // its residual bound beta_k |s_k| estimates omega_max^2 from slightly above; a plain power
  // iteration converges too slowly on the valve's clustered top spectrum (several slivers).
  const Eigen::Index n = elements_->reference_positions().cols();
  // Deterministic pseudo-random vectors (xorshift seeded by the step), so a restored state
  // repeats exactly the same calibration.
  const auto random_matrix = [n](std::uint64_t seed) {
    Eigen::Matrix3Xd r(3, n);
    seed = seed * 0x9e3779b97f4a7c15ULL + 0x2545f4914f6cdd1dULL;
    for (Eigen::Index i = 0; i < r.size(); ++i) {
      seed ^= seed << 13;
      seed ^= seed >> 7;
      seed ^= seed << 17;
      r.data()[i] = static_cast<double>(seed % 2001) / 1000.0 - 1.0;
    }
    return r;
  };
  Eigen::Matrix3Xd& v = state_.power_vector;
  if (v.cols() != n) v = random_matrix(0);
  const Eigen::ArrayXd mass = elements_->nodal_mass().array();
  const auto m_dot = [&](const Eigen::Matrix3Xd& p, const Eigen::Matrix3Xd& q) {
    return ((p.cwiseProduct(q)).colwise().sum().transpose().array() * mass).sum();
  };
  const Eigen::Matrix3Xd& reference = elements_->reference_positions();
  const double size = (reference.rowwise().maxCoeff() - reference.rowwise().minCoeff()).norm();
  const int k_max = std::max(2, options_.power_iterations);
  lanczos_basis_.resize(static_cast<std::size_t>(k_max + 1));
  std::vector<double> alpha, beta;
  // A cold random start each time: a warm start from the last Ritz vector converged to that
  // mode and missed a sliver that had become the stiffest (measured on the valve sector).
  Eigen::Matrix3Xd& q0 = lanczos_basis_[0];
  q0 = random_matrix(static_cast<std::uint64_t>(state_.step) + 1);
  apply_constraints(q0);
  double norm = std::sqrt(m_dot(q0, q0));
  if (!(norm > 0.0)) return;
  q0 /= norm;
  double theta = 0.0, bound = 0.0;
  Eigen::VectorXd ritz_vector;
  int k = 0;
  for (; k < k_max; ++k) {
    const Eigen::Matrix3Xd& q = lanczos_basis_[static_cast<std::size_t>(k)];
    const double h = 1e-7 * size / std::max(q.cwiseAbs().maxCoeff(), 1e-300);
    probe_position_ = state_.position + h * q;
    evaluate_internal_force(probe_position_, false, probe_force_, nullptr);
    probe_vector_ = ((probe_force_ - state_.internal_force) / h).array().rowwise() / mass.transpose();  // M^-1 K q
    apply_constraints(probe_vector_);
    alpha.push_back(m_dot(q, probe_vector_));
    for (int j = 0; j <= k; ++j) {  // full re-orthogonalisation (twice is enough)
      const Eigen::Matrix3Xd& qj = lanczos_basis_[static_cast<std::size_t>(j)];
      probe_vector_ -= m_dot(qj, probe_vector_) * qj;
    }
    for (int j = 0; j <= k; ++j) {
      const Eigen::Matrix3Xd& qj = lanczos_basis_[static_cast<std::size_t>(j)];
      probe_vector_ -= m_dot(qj, probe_vector_) * qj;
    }
    const double b = std::sqrt(std::max(m_dot(probe_vector_, probe_vector_), 0.0));
    // Ritz values of the tridiagonal T_k.
    const auto size_k = static_cast<Eigen::Index>(alpha.size());
    Eigen::MatrixXd T = Eigen::MatrixXd::Zero(size_k, size_k);
    for (Eigen::Index i = 0; i < size_k; ++i) {
      T(i, i) = alpha[static_cast<std::size_t>(i)];
      if (i + 1 < size_k) T(i, i + 1) = T(i + 1, i) = beta[static_cast<std::size_t>(i)];
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(T);
    theta = eig.eigenvalues()(size_k - 1);
    ritz_vector = eig.eigenvectors().col(size_k - 1);
    bound = b * std::abs(ritz_vector(size_k - 1));
    if (k >= 10 && bound <= 1e-4 * theta) {
      ++k;
      break;
    }
    if (!(b > 1e-10 * std::sqrt(std::abs(theta)))) {  // invariant subspace found
      ++k;
      break;
    }
    beta.push_back(b);
    lanczos_basis_[static_cast<std::size_t>(k + 1)] = probe_vector_ / b;
  }
  // Keep the Ritz vector for the next warm start.
  v.setZero();
  for (Eigen::Index i = 0; i < ritz_vector.size(); ++i) v += ritz_vector(i) * lanczos_basis_[static_cast<std::size_t>(i)];
  state_.calibrated_at_step = state_.step;
  state_.calibration_iterations = k;
  state_.element_step_at_calibration = element_step;
  const double lambda = theta + bound;
  if (lambda > 0.0) {
    state_.highest_frequency = std::sqrt(lambda);
    state_.calibrated_step = 2.0 / state_.highest_frequency;
  }
}

void ExplicitSolver::compute_external_force(double t, const Eigen::Matrix3Xd* nodal_forces) {
  Eigen::Matrix3Xd& f = state_.external_force;
  f.setZero();
  if (pressure_) {
    const double dp = pressure_(t);
    if (dp != 0.0) elements_->add_pressure_force(state_.position, dp, f);
  }
  if (nodal_forces != nullptr) {
    if (nodal_forces->cols() != f.cols()) {
      throw std::invalid_argument(fmt::format("solid: nodal forces for {} nodes, the mesh has {}",
                                              nodal_forces->cols(), f.cols()));
    }
    f += *nodal_forces;
  }
}

void ExplicitSolver::update_kinetic_energy() {
  double kinetic = 0.0;
  for (Eigen::Index i = 0; i < state_.velocity.cols(); ++i) {
    kinetic += 0.5 * elements_->nodal_mass()(i) * state_.velocity.col(i).squaredNorm();
  }
  state_.energy.kinetic = kinetic;
}

void ExplicitSolver::advance_window(double t_end, const Eigen::Matrix3Xd* nodal_forces) {
  if (t_end < state_.time) {
    throw std::invalid_argument(
        fmt::format("solid: advance_window to t = {} s, before the current time {} s", t_end, state_.time));
  }
  if (!internal_force_current_) {
    compute_internal_force(true);
    compute_contact_force();
    if (state_.step == 0) {
      update_kinetic_energy();
      state_.energy.initial_kinetic = state_.energy.kinetic;
    }
  }
  const Eigen::ArrayXd inverse_mass = elements_->nodal_mass().array().inverse();
  Eigen::Matrix3Xd& x = state_.position;
  Eigen::Matrix3Xd& v_half = state_.half_step_velocity;
  Eigen::Matrix3Xd& a = acceleration_;
  if (nodal_forces != nullptr && t_end > state_.time) {
    // The coupler's book of this window's load work: the load times the velocity sent at the
    // window's start, over the window (coupling_schemes.cpp, power_solid).
    state_.energy.interface_work += nodal_forces->cwiseProduct(state_.velocity).sum() * (t_end - state_.time);
  }
  // A coupled window's load starts at its start: the previous load acted over the half step
  // before it (the end-of-window velocity already holds that half kick), this one over the half
  // step after it (kick-drift-kick across the load's jump). Kicking the whole averaged step
  // with the new load missed 1/2 dt dF . v in the energy ledger at every window boundary.
  bool window_boundary = nodal_forces != nullptr && state_.step > 0;
  while (state_.time < t_end) {
    if (implicit()) {
      advance_window_implicit(t_end, nodal_forces);  // (AUTOMATIC: returns early when it switches back)
      continue;
    }
    compute_external_force(state_.time, nodal_forces);
    compute_acceleration(inverse_mass);

    // A penalty spring of k = factor m omega^2 raises the node's frequency by sqrt(1 + factor).
    double dt = !has_contact() ? state_.stable_step
                                        : state_.stable_step / std::sqrt(1.0 + options_.contact_stiffness_factor);
    // The step may fall at once but grows slowly: a step that follows the flutter of the
    // critical element up and down pumps energy into it (parametric excitation).
    if (options_.max_time_step_growth > 0.0 && state_.uncut_step > 0.0) {
      dt = std::min(dt, state_.uncut_step * (1.0 + options_.max_time_step_growth));
    }
    state_.uncut_step = dt;
    // Land exactly on t_end. Coupling windows (a few steps each) are cut into equal steps:
    // averaged-step central differences are not stable up to omega dt = 2 for a repeating uneven
    // pattern, and "full steps, the last two split evenly" gave each 13 us window of 2.25 steps
    // [dt, 0.62 dt, 0.62 dt], growing modes at omega dt ~ 1.3 by 1.21 per window (coupled 2D
    // leaflet at mu = 20, docs/solid_fe.md "Equal steps in a coupling window"). FE-only output
    // intervals (~100 steps) and forced steps (a diagnostic) keep that rule, bit for bit.
    const double remaining = t_end - state_.time;
    if (nodal_forces != nullptr && options_.fixed_time_step <= 0.0) {
      dt = remaining / std::max(1.0, std::ceil(remaining / dt * (1.0 - 1e-12)));
    } else if (remaining <= dt) {
      dt = remaining;
    } else if (remaining < 2.0 * dt) {
      dt = 0.5 * remaining;
    }
    const double averaged_step = 0.5 * (state_.last_step + dt);
    // The damping force at t_n (this step's start), where the pressure's sign is read.
    const double alpha = mass_damping_at(state_.time);
    if (alpha > 0.0) {
      // Central difference with damping force alpha m v at the full step, v the mean of the
      // two half-step velocities (implicit in v).
      previous_half_velocity_ = v_half;
      if (window_boundary) {
        v_half = ((1.0 - 0.5 * alpha * averaged_step) * v_half + (state_.velocity - v_half) + 0.5 * dt * a) /
                 (1.0 + 0.5 * alpha * averaged_step);
      } else {
        v_half = ((1.0 - 0.5 * alpha * averaged_step) * v_half + averaged_step * a) /
                 (1.0 + 0.5 * alpha * averaged_step);
      }
    } else if (window_boundary) {
      v_half = state_.velocity + 0.5 * dt * a;
    } else {
      v_half += averaged_step * a;
    }
    window_boundary = false;
    apply_constraints(v_half);
    Eigen::Matrix3Xd& dx = step_increment_;  // no allocation per step
    dx.noalias() = dt * v_half;
    if (alpha > 0.0) {
      for (Eigen::Index i = 0; i < x.cols(); ++i) {
        state_.energy.damping_work +=
            alpha * elements_->nodal_mass()(i) * 0.5 * (v_half.col(i) + previous_half_velocity_.col(i)).dot(dx.col(i));
      }
    }
    add_work(dx);
    x += dx;
    state_.time = (dt == remaining) ? t_end : state_.time + dt;
    ++state_.step;
    state_.last_step = dt;

    const bool estimate = state_.step % options_.time_step_update_interval == 0 || state_.stiffening_ahead;
    compute_internal_force(estimate);
    compute_contact_force();
    compute_external_force(state_.time, nodal_forces);
    add_work(dx);
    compute_acceleration(inverse_mass);
    state_.velocity = v_half + 0.5 * dt * a;
    update_kinetic_energy();
    state_.energy.update_largest_energy();
    if (step_observer_) step_observer_(state_);
    if (options_.max_energy_balance_error > 0.0 && state_.step >= kEnergyCheckFirstStep) check_energy_growth();
    if (automatic()) update_slow_velocity(dt);
    if (automatic() && settled_for_implicit()) {
      // The implicit integrator starts from x, v at this step and the acceleration of the
      // equation of motion there, with its first step (the settled state's own steps follow).
      state_.implicit_phase = true;
      state_.acceleration.resize(3, 0);
      state_.implicit_step = 0;
      state_.implicit_switch_pressure = pressure_ ? pressure_(state_.time) : 0.0;
      state_.chatter_damped = false;
      ++state_.switches;
      start_cost_rule();
      drop_kept_tangent();
    }
  }
}

double ExplicitSolver::mass_damping_at(double t) const {
  if (options_.diastolic_mass_damping_per_s > 0.0 && pressure_ && pressure_(t) < -options_.diastolic_damping_onset_Pa) {
    return options_.diastolic_mass_damping_per_s;
  }
  return options_.mass_damping_per_s;
}

int ExplicitSolver::pressure_sign(double t) const {
  const double p = pressure_ ? pressure_(t) : 0.0;
  return (p > 0.0) - (p < 0.0);
}

void ExplicitSolver::update_slow_velocity(double h) {
  const double tau = options_.settled_filter_time;
  if (tau <= 0.0) return;
  Eigen::Matrix3Xd& slow = state_.slow_velocity;
  if (slow.cols() != state_.velocity.cols()) {
    slow = state_.velocity;
  } else {
    // Backward Euler of d(slow)/dt = (v - slow) / tau: stable for any step, explicit or implicit.
    slow += (h / (tau + h)) * (state_.velocity - slow);
  }
  double kinetic = 0.0;
  for (Eigen::Index i = 0; i < slow.cols(); ++i) kinetic += 0.5 * elements_->nodal_mass()(i) * slow.col(i).squaredNorm();
  state_.slow_kinetic = kinetic;
}

bool ExplicitSolver::settled_for_implicit() {
  const EnergyBalance& e = state_.energy;
  // A model that holds no strain energy (at rest and unloaded, or still starting) is not settled.
  const bool settled =
      e.strain_energy > energy_check_floor_ &&
      (options_.settled_filter_time > 0.0 ? state_.slow_kinetic : e.kinetic) <= options_.settled_kinetic_ratio * e.strain_energy;
  if (!settled) {
    state_.settled_since = -1.0;
    return false;
  }
  if (state_.settled_since < 0.0) state_.settled_since = state_.time;
  return state_.time - state_.settled_since >= options_.settled_hold;
}

bool ExplicitSolver::moving_again() {
  const EnergyBalance& e = state_.energy;
  const double at_switch = state_.implicit_switch_pressure;
  if (pressure_sign(state_.time) != (at_switch > 0.0) - (at_switch < 0.0)) return true;
  const double moving = options_.moving_kinetic_ratio * e.strain_energy;
  if (options_.settled_filter_time <= 0.0) return e.kinetic > moving;
  if (state_.slow_kinetic > moving) return true;
  if (!state_.chatter_damped) {
    state_.chatter_damped = e.kinetic <= moving;
    return false;
  }
  return e.kinetic > moving;
}

void ExplicitSolver::switch_to_explicit() {
  // Central differences restart from the full-step velocity (the first step's averaged step is
  // then half a step: v(1/2) = v + dt/2 a) with a fresh step estimate of the present state.
  state_.implicit_phase = false;
  state_.settled_since = -1.0;
  ++state_.switches;
  state_.half_step_velocity = state_.velocity;
  state_.last_step = 0.0;
  state_.uncut_step = 0.0;
  state_.calibrated_at_step = -1;
  state_.stiffening_ahead = false;
  compute_internal_force(true);
  compute_contact_force();
}

double ExplicitSolver::energy_growth_measure() const {
  const EnergyBalance& e = state_.energy;
  // Relative to the largest energy seen, but never to less than the model's energy floor: below
  // it the ledger holds round-off-sized energies whose relative error means nothing (a coupled
  // 2D leaflet was stopped at 0.218 of 8.6e-14 J before it had moved).
  const double scale = std::max(e.largest_energy, energy_check_floor_);
  // The balance closes for both integrators (implicit: to the Newton residual's work, since the
  // scheme's dissipation is booked from its energy identity). Implicit steps may also create
  // energy on their own (negative dissipation beyond the part from the loads' window steps, which
  // is the coupling's exchange and is watched by the coupler): that counts as growth too.
  const double scheme_created = std::max(0.0, e.load_step_dissipation - e.numerical_dissipation);
  return std::max(std::abs(e.balance()), scheme_created) / scale;
}

void ExplicitSolver::check_energy_growth() const {
  const EnergyBalance& e = state_.energy;
  const double error = energy_growth_measure();
  if (error <= options_.max_energy_balance_error) return;  // (a NaN balance stops too)
  // Where the kinetic energy sits: the node with the most, and its share of the total.
  const Eigen::VectorXd& mass = elements_->nodal_mass();
  Eigen::Index hottest = 0;
  double hottest_energy = -1.0;
  for (Eigen::Index i = 0; i < state_.velocity.cols(); ++i) {
    const double k = 0.5 * mass(i) * state_.velocity.col(i).squaredNorm();
    if (k > hottest_energy) {
      hottest_energy = k;
      hottest = i;
    }
  }
  const Eigen::Vector3d x = state_.position.col(hottest);
  throw EnergyGrowthError(
      fmt::format(
          "solid: energy growth at t = {:.6g} s, step {}: the energy balance error is {:.3g} of the largest energy "
          "seen ({:.4g} J; at least the model's floor {:.3g} J), above solid.max_energy_balance_error = {:.3g}. Energies (J): kinetic {:.4g}, strain {:.4g}, "
          "internal work {:.4g}, external work {:.4g}, contact work {:.4g}, damping work {:.4g}, tie work {:.4g}, "
          "numerical dissipation {:.4g} (of which the loads' window steps {:.4g}), balance {:.4g}. Kinetic energy concentrates at node {} (at [{:.4g}, {:.4g}, {:.4g}] m, {:.3g} J = {:.1f} % "
          "of it); dt = {:.3g} s (element {}, calibration x{:.2f}), {} nodes in contact. The time integration is "
          "creating energy: lower solid.time_step_safety (now {:.3g}) or solid.max_time_step_growth (now {:.3g}), "
          "lower solid.contact_stiffness_factor (now {:.3g}) if the node is in contact, or damp the flutter with "
          "solid.mass_damping_per_s (now {:.3g}); 0 turns this check off.",
          state_.time, state_.step, error, e.largest_energy, energy_check_floor_, options_.max_energy_balance_error, e.kinetic,
          e.strain_energy, e.internal_work, e.external_work, e.contact_work, e.damping_work, e.tie_work,
          e.numerical_dissipation, e.load_step_dissipation, e.balance(),
          hottest, x.x(), x.y(), x.z(), hottest_energy, 100.0 * hottest_energy / std::max(e.kinetic, 1e-300),
          state_.stable_step, state_.critical_element, state_.step_calibration, state_.nodes_in_contact,
          step_factor_ > 0.0 ? step_factor_ : options_.time_step_safety, options_.max_time_step_growth,
          options_.contact_stiffness_factor, options_.mass_damping_per_s),
      hottest);
}

void ExplicitSolver::add_work(const Eigen::Matrix3Xd& dx) {
  // Trapezoidal increments: half with the forces before the step, half with those after.
  state_.energy.internal_work += 0.5 * state_.internal_force.cwiseProduct(dx).sum();
  if (state_.hourglass_force.cols() == dx.cols()) {
    state_.energy.hourglass_work += 0.5 * state_.hourglass_force.cwiseProduct(dx).sum();
  }
  state_.energy.external_work += 0.5 * state_.external_force.cwiseProduct(dx).sum();
  state_.energy.contact_work -= 0.5 * state_.contact_force.cwiseProduct(dx).sum();
  if (tie_) state_.energy.tie_work -= 0.5 * state_.tie_force.cwiseProduct(dx).sum();
}

}  // namespace valvefsi::solid
