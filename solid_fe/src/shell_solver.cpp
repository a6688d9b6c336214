#include "valvefsi/solid/shell_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>
#include <omp.h>

#include "valvefsi/solid/material_error.hpp"
#include "valvefsi/solid/shell_forces.hpp"

namespace valvefsi::solid {
namespace {
constexpr std::int64_t kMinElementsForThreads = 1000;
}  // namespace

double EnergyBalance::relative_balance_error() const {
  const double scale = std::max({std::abs(kinetic), std::abs(internal_work), std::abs(external_work),
                                 std::abs(damping_work), std::abs(contact_work), std::abs(initial_kinetic),
                                 1e-300});
  return std::abs(balance()) / scale;
}

ShellSolver::ShellSolver(ShellModel model, Material material, SolverOptions options)
    : model_(std::move(model)), material_(std::move(material)), options_(options) {
  if (!(options_.time_step_safety > 0.0 && options_.time_step_safety <= 1.0)) {
    throw std::invalid_argument(fmt::format(
        "solid: time_step_safety = {}: allowed (0, 1]", options_.time_step_safety));
  }
  if (options_.time_step_update_interval < 1) {
    throw std::invalid_argument(fmt::format(
        "solid: time_step_update_interval = {}: allowed >= 1", options_.time_step_update_interval));
  }
  const Eigen::Index n = model_.reference_positions.cols();
  state_.position = model_.reference_positions;
  state_.half_step_velocity = Eigen::Matrix3Xd::Zero(3, n);
  state_.velocity = Eigen::Matrix3Xd::Zero(3, n);
  state_.internal_force = Eigen::Matrix3Xd::Zero(3, n);
  state_.external_force = Eigen::Matrix3Xd::Zero(3, n);
  state_.contact_force = Eigen::Matrix3Xd::Zero(3, n);
  half_thickness_ = Eigen::VectorXd::Zero(n);
  for (const auto& el : model_.elements) {
    for (const auto a : el.nodes) half_thickness_(a) = std::max(half_thickness_(a), 0.5 * el.thickness);
  }
  acceleration_ = Eigen::Matrix3Xd::Zero(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!(model_.nodal_mass(i) > 0.0)) {
      throw std::invalid_argument(fmt::format("solid: node {} belongs to no element (zero mass)", i));
    }
  }
}

void ShellSolver::set_pressure(std::function<double(double)> pressure_Pa, std::vector<std::int64_t> elements) {
  pressure_ = std::move(pressure_Pa);
  if (elements.empty()) {
    elements.resize(model_.elements.size());
    for (std::size_t e = 0; e < elements.size(); ++e) elements[e] = static_cast<std::int64_t>(e);
  }
  for (const std::int64_t e : elements) {
    if (e < 0 || e >= static_cast<std::int64_t>(model_.elements.size())) {
      throw std::invalid_argument(fmt::format("solid: pressure element {} does not exist", e));
    }
  }
  pressure_elements_ = std::move(elements);
  internal_force_current_ = false;
}

void ShellSolver::add_symmetry_constraints(const std::vector<SymmetryConstraint>& constraints) {
  for (const auto& c : constraints) symmetry_.push_back({c.node, c.normal.normalized()});
}

void ShellSolver::add_contact_plane(const Plane& plane) {
  contact_planes_.push_back({plane.point, plane.normal.normalized()});
  internal_force_current_ = false;
}

void ShellSolver::enable_leaflet_contact(std::vector<int> surface_of_node) {
  leaflet_contact_.emplace(model_, std::move(surface_of_node));
  internal_force_current_ = false;
}

void ShellSolver::add_contact_cylinder(const ContactCylinder& cylinder) {
  if (!(cylinder.radius > 0.0) || !(cylinder.axis.norm() > 0.0)) {
    throw std::invalid_argument(fmt::format("solid: contact cylinder radius {} m, axis norm {}: allowed > 0",
                                            cylinder.radius, cylinder.axis.norm()));
  }
  contact_cylinders_.push_back({cylinder.origin, cylinder.axis.normalized(), cylinder.radius});
  internal_force_current_ = false;
}

void ShellSolver::set_strip_ties(std::vector<StripTie> ties) {
  const Eigen::Index n = model_.reference_positions.cols();
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

void ShellSolver::compute_contact_force() {
  Eigen::Matrix3Xd& f = state_.contact_force;
  f.setZero();
  state_.nodes_in_contact = 0;
  if (!has_contact()) return;
  // Penalty stiffness from the highest frequency the first step resolves, k = factor m (2/dt)^2,
  // then kept: a constant spring is conservative, and the step only shrinks as tissue stiffens.
  if (contact_omega2_ == 0.0) {
    const double dt_critical = state_.stable_step / options_.time_step_safety;
    contact_omega2_ = 4.0 / (dt_critical * dt_critical);
  }
  const double omega2 = contact_omega2_;
  const Eigen::Matrix3Xd& x = state_.position;
  for (const Plane& plane : contact_planes_) {
    for (Eigen::Index i = 0; i < x.cols(); ++i) {
      const double gap = (x.col(i) - plane.point).dot(plane.normal) - half_thickness_(i);
      if (gap < 0.0 && !model_.fixed[static_cast<std::size_t>(i)]) {
        f.col(i) -= options_.contact_stiffness_factor * model_.nodal_mass(i) * omega2 * gap * plane.normal;
        ++state_.nodes_in_contact;
      }
    }
  }
  for (const ContactCylinder& cylinder : contact_cylinders_) {
    for (Eigen::Index i = 0; i < x.cols(); ++i) {
      if (model_.fixed[static_cast<std::size_t>(i)]) continue;
      const Eigen::Vector3d d = x.col(i) - cylinder.origin;
      const Eigen::Vector3d radial = d - d.dot(cylinder.axis) * cylinder.axis;
      const double r = radial.norm();
      const double penetration = r + half_thickness_(i) - cylinder.radius;
      if (penetration > 0.0 && r > 0.0) {
        f.col(i) -= options_.contact_stiffness_factor * model_.nodal_mass(i) * omega2 * penetration * (radial / r);
        ++state_.nodes_in_contact;
      }
    }
  }
  if (leaflet_contact_) {
    state_.nodes_in_contact +=
        leaflet_contact_->add_forces(model_, x, options_.contact_stiffness_factor * omega2, f);
  }
}

void ShellSolver::set_velocity(const Eigen::Matrix3Xd& velocity) {
  state_.velocity = velocity;
  state_.half_step_velocity = velocity;
  apply_constraints(state_.velocity);
  apply_constraints(state_.half_step_velocity);
  internal_force_current_ = false;
}

void ShellSolver::apply_constraints(Eigen::Matrix3Xd& field) const {
  if (planar_) {
    field.row(2).setZero();
    for (const auto& t : ties_) {
      const double ma = model_.nodal_mass(t.front), mb = model_.nodal_mass(t.back);
      const Eigen::Vector3d mean = (ma * field.col(t.front) + mb * field.col(t.back)) / (ma + mb);
      field.col(t.front) = mean;
      field.col(t.back) = mean;
    }
  }
  for (const auto& c : symmetry_) {
    auto col = field.col(c.node);
    col -= col.dot(c.normal) * c.normal;
  }
  for (std::size_t i = 0; i < model_.fixed.size(); ++i) {
    if (model_.fixed[i]) field.col(static_cast<Eigen::Index>(i)).setZero();
  }
}

double ShellSolver::evaluate_internal_force(const Eigen::Matrix3Xd& x, bool estimate_step, Eigen::Matrix3Xd& out,
                                            double& min_step, std::int64_t& critical) {
  const int threads = omp_get_max_threads();
  const Eigen::Index n = model_.reference_positions.cols();
  if (static_cast<int>(thread_forces_.size()) != threads) {
    thread_forces_.assign(static_cast<std::size_t>(threads), Eigen::Matrix3Xd::Zero(3, n));
  }
  const auto num_elements = static_cast<std::int64_t>(model_.elements.size());
  double strain_energy = 0.0;
  min_step = std::numeric_limits<double>::infinity();
  critical = -1;
  std::string error;
  std::visit(
      [&](const auto& law) {
        // Small models run serially: thread start-up would cost more than it saves.
#pragma omp parallel if (num_elements >= kMinElementsForThreads)
        {
          Eigen::Matrix3Xd& f = thread_forces_[static_cast<std::size_t>(omp_get_thread_num())];
          f.setZero();
          double local_energy = 0.0;
          double local_step = std::numeric_limits<double>::infinity();
          std::int64_t local_critical = -1;
#pragma omp for schedule(static)
          for (std::int64_t e = 0; e < num_elements; ++e) {
            try {
              const ElementResult r = add_element_internal_force(
                  model_, model_.elements[static_cast<std::size_t>(e)], law, x, f, estimate_step);
              local_energy += r.strain_energy;
              if (r.stable_step < local_step) {
                local_step = r.stable_step;
                local_critical = e;
              }
            } catch (const MaterialStateError& ex) {
#pragma omp critical(valvefsi_solid_error)
              if (error.empty()) error = fmt::format("element {}: {}", e, ex.what());
            }
          }
#pragma omp critical(valvefsi_solid_reduce)
          {
            strain_energy += local_energy;
            if (local_step < min_step) {
              min_step = local_step;
              critical = local_critical;
            }
          }
        }
      },
      material_);
  if (!error.empty()) {
    throw MaterialStateError(fmt::format("solid at t = {:.6g} s, step {}: {}", state_.time, state_.step, error));
  }
  if (out.cols() != n) out.resize(3, n);
  out = thread_forces_[0];
  for (std::size_t t = 1; t < thread_forces_.size(); ++t) out += thread_forces_[t];
  return strain_energy;
}

void ShellSolver::compute_internal_force(bool estimate_step) {
  double min_step = 0;
  std::int64_t critical = -1;
  state_.energy.strain_energy =
      evaluate_internal_force(state_.position, estimate_step, state_.internal_force, min_step, critical);
  if (options_.fixed_time_step > 0.0) {
    state_.stable_step = options_.fixed_time_step;
  } else if (estimate_step) {
    // Element estimate (always below the true critical step), or, when calibrating, the
    // model's own critical step 2/omega_max from the last Lanczos run, scaled down (never up)
    // by how much the element estimate fell since then, so stiffening between calibrations
    // is followed; a fall below 70 % triggers a new calibration.
    double critical_step = min_step;
    const int interval = options_.time_step_calibration_interval;
    if (interval > 0) {
      const bool due = state_.calibrated_at_step < 0 || state_.step - state_.calibrated_at_step >= interval ||
                       min_step < 0.7 * state_.element_step_at_calibration;
      if (due) calibrate_stable_step(min_step);
      if (state_.calibrated_step > 0.0) {
        critical_step = std::clamp(
            state_.calibrated_step * std::min(1.0, min_step / state_.element_step_at_calibration), min_step,
            options_.max_step_calibration * min_step);
      }
      state_.step_calibration = critical_step / min_step;
    }
    state_.stable_step = std::min(options_.time_step_safety * critical_step, options_.max_time_step);
    state_.critical_element = critical;
  }
  internal_force_current_ = true;
}

void ShellSolver::calibrate_stable_step(double element_step) {
  // Lanczos on M^-1 K in the mass inner product (symmetric there), K q by a forward difference
  // of the internal force, full re-orthogonalisation (few vectors). The largest Ritz value plus
  // its residual bound beta_k |s_k| estimates omega_max^2 from slightly above; a plain power
  // iteration converges too slowly on the valve's clustered top spectrum (several slivers).
  const Eigen::Index n = model_.reference_positions.cols();
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
  const Eigen::ArrayXd mass = model_.nodal_mass.array();
  const auto m_dot = [&](const Eigen::Matrix3Xd& p, const Eigen::Matrix3Xd& q) {
    return ((p.cwiseProduct(q)).colwise().sum().transpose().array() * mass).sum();
  };
  const double size = (model_.reference_positions.rowwise().maxCoeff() -
                       model_.reference_positions.rowwise().minCoeff()).norm();
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
  double unused_step = 0;
  std::int64_t unused_element = -1;
  double theta = 0.0, bound = 0.0;
  Eigen::VectorXd ritz_vector;
  int k = 0;
  for (; k < k_max; ++k) {
    const Eigen::Matrix3Xd& q = lanczos_basis_[static_cast<std::size_t>(k)];
    const double h = 1e-7 * size / std::max(q.cwiseAbs().maxCoeff(), 1e-300);
    probe_position_ = state_.position + h * q;
    evaluate_internal_force(probe_position_, false, probe_force_, unused_step, unused_element);
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

void ShellSolver::compute_external_force(double t, const Eigen::Matrix3Xd* nodal_forces) {
  Eigen::Matrix3Xd& f = state_.external_force;
  f.setZero();
  if (pressure_) {
    const double dp = pressure_(t);
    if (dp != 0.0) {
      const Eigen::Matrix3Xd& x = state_.position;
      for (const std::int64_t e : pressure_elements_) {
        const auto& nodes = model_.elements[static_cast<std::size_t>(e)].nodes;
        const Eigen::Vector3d area_vector =
            0.5 * (x.col(nodes[1]) - x.col(nodes[0])).cross(x.col(nodes[2]) - x.col(nodes[0]));
        const Eigen::Vector3d share = (dp / 3.0) * area_vector;
        for (int a = 0; a < 3; ++a) f.col(nodes[a]) += share;
      }
    }
  }
  if (nodal_forces != nullptr) {
    if (nodal_forces->cols() != f.cols()) {
      throw std::invalid_argument(fmt::format("solid: nodal forces for {} nodes, the mesh has {}",
                                              nodal_forces->cols(), f.cols()));
    }
    f += *nodal_forces;
  }
}

void ShellSolver::update_kinetic_energy() {
  double kinetic = 0.0;
  for (Eigen::Index i = 0; i < state_.velocity.cols(); ++i) {
    kinetic += 0.5 * model_.nodal_mass(i) * state_.velocity.col(i).squaredNorm();
  }
  state_.energy.kinetic = kinetic;
}

void ShellSolver::advance_window(double t_end, const Eigen::Matrix3Xd* nodal_forces) {
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
  const Eigen::ArrayXd inverse_mass = model_.nodal_mass.array().inverse();
  const double alpha = options_.mass_damping_per_s;
  Eigen::Matrix3Xd& x = state_.position;
  Eigen::Matrix3Xd& v_half = state_.half_step_velocity;
  Eigen::Matrix3Xd& a = acceleration_;

  while (state_.time < t_end) {
    compute_external_force(state_.time, nodal_forces);
    a = (state_.external_force + state_.contact_force - state_.internal_force).array().rowwise() *
        inverse_mass.transpose();
    apply_constraints(a);

    // A penalty spring of k = factor m omega^2 raises the node's frequency by sqrt(1 + factor).
    double dt = !has_contact() ? state_.stable_step
                                        : state_.stable_step / std::sqrt(1.0 + options_.contact_stiffness_factor);
    // The step may fall at once but grows slowly: a step that follows the flutter of the
    // critical element up and down pumps energy into it (parametric excitation).
    if (options_.max_time_step_growth > 0.0 && state_.last_step > 0.0) {
      dt = std::min(dt, state_.last_step * (1.0 + options_.max_time_step_growth));
    }
    // Land exactly on t_end; avoid a sliver step by splitting the last two evenly.
    const double remaining = t_end - state_.time;
    if (remaining <= dt) {
      dt = remaining;
    } else if (remaining < 2.0 * dt) {
      dt = 0.5 * remaining;
    }
    const double averaged_step = 0.5 * (state_.last_step + dt);
    if (alpha > 0.0) {
      // Central difference with damping force alpha m v at the full step, v the mean of the
      // two half-step velocities (implicit in v).
      previous_half_velocity_ = v_half;
      v_half = ((1.0 - 0.5 * alpha * averaged_step) * v_half + averaged_step * a) /
               (1.0 + 0.5 * alpha * averaged_step);
    } else {
      v_half += averaged_step * a;
    }
    apply_constraints(v_half);
    Eigen::Matrix3Xd& dx = step_increment_;  // no allocation per step
    dx.noalias() = dt * v_half;
    if (alpha > 0.0) {
      for (Eigen::Index i = 0; i < x.cols(); ++i) {
        state_.energy.damping_work +=
            alpha * model_.nodal_mass(i) * 0.5 * (v_half.col(i) + previous_half_velocity_.col(i)).dot(dx.col(i));
      }
    }
    state_.energy.internal_work += 0.5 * (state_.internal_force.cwiseProduct(dx)).sum();
    state_.energy.external_work += 0.5 * (state_.external_force.cwiseProduct(dx)).sum();
    state_.energy.contact_work -= 0.5 * (state_.contact_force.cwiseProduct(dx)).sum();
    x += dx;
    state_.time = (dt == remaining) ? t_end : state_.time + dt;
    ++state_.step;
    state_.last_step = dt;

    const bool estimate = state_.step % options_.time_step_update_interval == 0;
    compute_internal_force(estimate);
    compute_contact_force();
    compute_external_force(state_.time, nodal_forces);
    state_.energy.internal_work += 0.5 * (state_.internal_force.cwiseProduct(dx)).sum();
    state_.energy.external_work += 0.5 * (state_.external_force.cwiseProduct(dx)).sum();
    state_.energy.contact_work -= 0.5 * (state_.contact_force.cwiseProduct(dx)).sum();
    a = (state_.external_force + state_.contact_force - state_.internal_force).array().rowwise() *
        inverse_mass.transpose();
    apply_constraints(a);
    state_.velocity = v_half + 0.5 * dt * a;
    update_kinetic_energy();
  }
}

void ShellSolver::element_fields(Eigen::VectorXd& max_principal_stress,
                                 Eigen::VectorXd& max_principal_log_strain) const {
  const auto num_elements = static_cast<Eigen::Index>(model_.elements.size());
  max_principal_stress.resize(num_elements);
  max_principal_log_strain.resize(num_elements);
  std::visit(
      [&](const auto& law) {
#pragma omp parallel for schedule(static) if (num_elements >= kMinElementsForThreads)
        for (Eigen::Index e = 0; e < num_elements; ++e) {
          try {
            const ElementFieldValues v =
                element_field_values(model_, model_.elements[static_cast<std::size_t>(e)], law, state_.position);
            max_principal_stress(e) = v.max_principal_stress;
            max_principal_log_strain(e) = v.max_principal_log_strain;
          } catch (const MaterialStateError&) {
            // Output of a state the solver could not evaluate: mark it rather than stop.
            max_principal_stress(e) = std::numeric_limits<double>::quiet_NaN();
            max_principal_log_strain(e) = std::numeric_limits<double>::quiet_NaN();
          }
        }
      },
      material_);
}

}  // namespace valvefsi::solid
