#include "valvefsi/solid/hexahedron_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <utility>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>
#include <omp.h>

#include "valvefsi/solid/material_error.hpp"

namespace valvefsi::solid {
namespace {
constexpr std::int64_t kMinElementsForThreads = 1000;
constexpr std::array<std::array<double, 2>, 4> kFaceSigns{{{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}};
}  // namespace

double HexahedronEnergy::relative_balance_error() const {
  const double scale = std::max({std::abs(kinetic), std::abs(internal_work), std::abs(external_work),
                                 std::abs(damping_work), std::abs(contact_work), std::abs(initial_kinetic), 1e-300});
  return std::abs(balance()) / scale;
}

HexahedronModel build_hexahedron_model(const Mesh& mesh, const HexahedronModelOptions& options,
                                       const std::string& source) {
  if (mesh.hexahedra.empty()) {
    throw std::invalid_argument(fmt::format("{}: /mesh/hexahedra is missing or empty", source));
  }
  if (!(options.density > 0.0)) {
    throw std::invalid_argument(fmt::format("{}: density = {}: allowed > 0", source, options.density));
  }
  const auto num = static_cast<Eigen::Index>(mesh.hexahedra.size());
  if (mesh.hexahedron_circumferential.cols() != num || mesh.hexahedron_radial.cols() != num) {
    throw std::invalid_argument(fmt::format(
        "{}: /mesh/hexahedron_axes has {} circumferential and {} radial axes for {} hexahedra", source,
        mesh.hexahedron_circumferential.cols(), mesh.hexahedron_radial.cols(), num));
  }
  HexahedronModel model;
  model.density = options.density;
  model.reference_positions = mesh.nodes;
  model.nodal_mass = Eigen::VectorXd::Zero(mesh.nodes.cols());
  model.elements.reserve(mesh.hexahedra.size());
  for (Eigen::Index e = 0; e < num; ++e) {
    const auto& nodes = mesh.hexahedra[static_cast<std::size_t>(e)];
    for (const std::int64_t n : nodes) {
      if (n < 0 || n >= mesh.nodes.cols()) {
        throw std::invalid_argument(fmt::format("{}: /mesh/hexahedra[{}] has node {}: allowed 0..{}", source, e, n,
                                                mesh.nodes.cols() - 1));
      }
    }
    try {
      model.elements.push_back(make_hex_element(nodes, mesh.nodes, mesh.hexahedron_circumferential.col(e),
                                                mesh.hexahedron_radial.col(e)));
    } catch (const std::invalid_argument& ex) {
      throw std::invalid_argument(fmt::format("{}: /mesh/hexahedra[{}]: {}", source, e, ex.what()));
    }
    for (const std::int64_t n : nodes) model.nodal_mass(n) += options.density * model.elements.back().volume / 8.0;
  }
  model.fixed.assign(static_cast<std::size_t>(mesh.nodes.cols()), 0);
  for (const std::int64_t n : options.fixed_nodes) {
    if (n < 0 || n >= mesh.nodes.cols()) {
      throw std::invalid_argument(fmt::format("{}: fixed node {}: allowed 0..{}", source, n, mesh.nodes.cols() - 1));
    }
    model.fixed[static_cast<std::size_t>(n)] = 1;
  }
  return model;
}

std::vector<PressureFace> ventricular_faces(const Mesh& mesh, const std::vector<std::int64_t>& elements) {
  std::set<std::array<std::int64_t, 4>> aortic;
  for (const auto& h : mesh.hexahedra) {
    std::array<std::int64_t, 4> top{h[4], h[5], h[6], h[7]};
    std::sort(top.begin(), top.end());
    aortic.insert(top);
  }
  std::vector<std::int64_t> chosen = elements;
  if (chosen.empty()) {
    chosen.resize(mesh.hexahedra.size());
    for (std::size_t e = 0; e < chosen.size(); ++e) chosen[e] = static_cast<std::int64_t>(e);
  }
  std::vector<PressureFace> faces;
  for (const std::int64_t e : chosen) {
    const auto& h = mesh.hexahedra.at(static_cast<std::size_t>(e));
    std::array<std::int64_t, 4> bottom{h[0], h[1], h[2], h[3]};
    std::array<std::int64_t, 4> key = bottom;
    std::sort(key.begin(), key.end());
    if (aortic.count(key) == 0) faces.push_back(bottom);
  }
  return faces;
}

HexahedronSolver::HexahedronSolver(HexahedronModel model, SolidMaterial material, HexahedronSolverOptions options)
    : model_(std::move(model)), material_(std::move(material)), options_(options) {
  if (!(options_.time_step_safety > 0.0 && options_.time_step_safety <= 1.0)) {
    throw std::invalid_argument(fmt::format("solid: time_step_safety = {}: allowed (0, 1]", options_.time_step_safety));
  }
  if (options_.time_step_update_interval < 1) {
    throw std::invalid_argument(fmt::format("solid: time_step_update_interval = {}: allowed >= 1",
                                            options_.time_step_update_interval));
  }
  const Eigen::Index n = model_.reference_positions.cols();
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!(model_.nodal_mass(i) > 0.0)) {
      throw std::invalid_argument(fmt::format("solid: node {} belongs to no hexahedron (zero mass)", i));
    }
  }
  state_.position = model_.reference_positions;
  for (Eigen::Matrix3Xd* m : {&state_.half_step_velocity, &state_.velocity, &state_.internal_force,
                              &state_.hourglass_force, &state_.external_force, &state_.contact_force, &acceleration_}) {
    *m = Eigen::Matrix3Xd::Zero(3, n);
  }
  const double mu = shear_modulus(material_), kappa = bulk_modulus(material_);
  state_.moduli.assign(model_.elements.size(), hex_moduli(mu, kappa));
}

void HexahedronSolver::set_pressure(std::function<double(double)> pressure_Pa, std::vector<PressureFace> faces) {
  for (const auto& face : faces) {
    for (const std::int64_t n : face) {
      if (n < 0 || n >= model_.reference_positions.cols()) {
        throw std::invalid_argument(fmt::format("solid: pressure face node {} does not exist", n));
      }
    }
  }
  pressure_ = std::move(pressure_Pa);
  pressure_faces_ = std::move(faces);
}

void HexahedronSolver::add_symmetry_constraints(const std::vector<SymmetryConstraint>& constraints) {
  for (const auto& c : constraints) symmetry_.push_back({c.node, c.normal.normalized()});
}

void HexahedronSolver::add_contact_plane(const Plane& plane) {
  contact_planes_.push_back({plane.point, plane.normal.normalized()});
}

void HexahedronSolver::set_velocity(const Eigen::Matrix3Xd& velocity) {
  state_.velocity = velocity;
  state_.half_step_velocity = velocity;
  apply_constraints(state_.velocity);
  apply_constraints(state_.half_step_velocity);
  internal_force_current_ = false;
}

void HexahedronSolver::apply_constraints(Eigen::Matrix3Xd& field) const {
  for (const auto& c : symmetry_) {
    auto col = field.col(c.node);
    col -= col.dot(c.normal) * c.normal;
  }
  for (std::size_t i = 0; i < model_.fixed.size(); ++i) {
    if (model_.fixed[i]) field.col(static_cast<Eigen::Index>(i)).setZero();
  }
}

void HexahedronSolver::compute_internal_force(bool estimate_step) {
  const int threads = omp_get_max_threads();
  const Eigen::Index n = model_.reference_positions.cols();
  if (static_cast<int>(thread_forces_.size()) != threads) {
    thread_forces_.assign(static_cast<std::size_t>(threads), Eigen::Matrix3Xd::Zero(3, n));
    thread_hourglass_.assign(static_cast<std::size_t>(threads), Eigen::Matrix3Xd::Zero(3, n));
  }
  const auto num_elements = static_cast<std::int64_t>(model_.elements.size());
  double strain_energy = 0.0, hourglass_energy = 0.0;
  double max_omega2 = 0.0;
  std::int64_t critical = -1;
  std::string error;
  const Eigen::Matrix3Xd& x = state_.position;
  const double density = model_.density;
  std::visit(
      [&](const auto& law) {
#pragma omp parallel if (num_elements >= kMinElementsForThreads)
        {
          const auto t = static_cast<std::size_t>(omp_get_thread_num());
          Eigen::Matrix3Xd& f = thread_forces_[t];
          Eigen::Matrix3Xd& fh = thread_hourglass_[t];
          f.setZero();
          fh.setZero();
          double local_energy = 0.0, local_hourglass = 0.0, local_omega2 = 0.0;
          std::int64_t local_critical = -1;
#pragma omp for schedule(static)
          for (std::int64_t e = 0; e < num_elements; ++e) {
            try {
              const auto ue = static_cast<std::size_t>(e);
              const HexElementResult r = hex_element_force(model_.elements[ue], law, x, density, state_.moduli[ue],
                                                           estimate_step, f, &fh);
              local_energy += r.strain_energy;
              local_hourglass += r.hourglass_energy;
              if (r.omega2 > local_omega2) {
                local_omega2 = r.omega2;
                local_critical = e;
              }
            } catch (const MaterialStateError& ex) {
#pragma omp critical(valvefsi_hex_error)
              if (error.empty()) error = fmt::format("hexahedron {}: {}", e, ex.what());
            }
          }
#pragma omp critical(valvefsi_hex_reduce)
          {
            strain_energy += local_energy;
            hourglass_energy += local_hourglass;
            if (local_omega2 > max_omega2) {
              max_omega2 = local_omega2;
              critical = local_critical;
            }
          }
        }
      },
      material_);
  if (!error.empty()) {
    throw MaterialStateError(fmt::format("solid at t = {:.6g} s, step {}: {}", state_.time, state_.step, error));
  }
  state_.internal_force = thread_forces_[0];
  state_.hourglass_force = thread_hourglass_[0];
  for (std::size_t t = 1; t < thread_forces_.size(); ++t) {
    state_.internal_force += thread_forces_[t];
    state_.hourglass_force += thread_hourglass_[t];
  }
  state_.energy.strain_energy = strain_energy;
  state_.energy.hourglass_energy = hourglass_energy;
  if (estimate_step) {
    const double critical_step = 2.0 / std::sqrt(max_omega2);
    const double factor = step_factor_ > 0.0 ? step_factor_ : options_.time_step_safety;
    state_.stable_step = std::min(factor * critical_step, options_.max_time_step);
    state_.critical_element = critical;
  }
  internal_force_current_ = true;
}

void HexahedronSolver::compute_external_force(double t, const Eigen::Matrix3Xd* nodal_forces) {
  Eigen::Matrix3Xd& f = state_.external_force;
  f.setZero();
  if (pressure_) {
    const double dp = pressure_(t);
    if (dp != 0.0) {
      const Eigen::Matrix3Xd& x = state_.position;
      const double g = 1.0 / std::sqrt(3.0);
      for (const auto& face : pressure_faces_) {
        // Consistent load of the bilinear face: f_a = dp int N_a (x,xi x x,eta) dxi deta (2x2 Gauss, exact).
        for (const auto& gp : kFaceSigns) {
          const double xi = g * gp[0], eta = g * gp[1];
          Eigen::Vector3d dxi = Eigen::Vector3d::Zero(), deta = Eigen::Vector3d::Zero();
          std::array<double, 4> N{};
          for (int a = 0; a < 4; ++a) {
            const auto& s = kFaceSigns[static_cast<std::size_t>(a)];
            N[static_cast<std::size_t>(a)] = 0.25 * (1 + s[0] * xi) * (1 + s[1] * eta);
            dxi += 0.25 * s[0] * (1 + s[1] * eta) * x.col(face[static_cast<std::size_t>(a)]);
            deta += 0.25 * s[1] * (1 + s[0] * xi) * x.col(face[static_cast<std::size_t>(a)]);
          }
          const Eigen::Vector3d area = dp * dxi.cross(deta);
          for (int a = 0; a < 4; ++a) f.col(face[static_cast<std::size_t>(a)]) += N[static_cast<std::size_t>(a)] * area;
        }
      }
    }
  }
  if (nodal_forces != nullptr) {
    if (nodal_forces->cols() != f.cols()) {
      throw std::invalid_argument(
          fmt::format("solid: nodal forces for {} nodes, the mesh has {}", nodal_forces->cols(), f.cols()));
    }
    f += *nodal_forces;
  }
}

void HexahedronSolver::compute_contact_force() {
  Eigen::Matrix3Xd& f = state_.contact_force;
  f.setZero();
  state_.nodes_in_contact = 0;
  if (contact_planes_.empty()) return;
  if (contact_omega2_ == 0.0) {
    const double dt_critical = state_.stable_step / options_.time_step_safety;
    contact_omega2_ = 4.0 / (dt_critical * dt_critical);
  }
  const Eigen::Matrix3Xd& x = state_.position;
  for (const Plane& plane : contact_planes_) {
    for (Eigen::Index i = 0; i < x.cols(); ++i) {
      const double gap = (x.col(i) - plane.point).dot(plane.normal);
      if (gap < 0.0 && !model_.fixed[static_cast<std::size_t>(i)]) {
        f.col(i) -= options_.contact_stiffness_factor * model_.nodal_mass(i) * contact_omega2_ * gap * plane.normal;
        ++state_.nodes_in_contact;
      }
    }
  }
}

void HexahedronSolver::update_kinetic_energy() {
  double kinetic = 0.0;
  for (Eigen::Index i = 0; i < state_.velocity.cols(); ++i) {
    kinetic += 0.5 * model_.nodal_mass(i) * state_.velocity.col(i).squaredNorm();
  }
  state_.energy.kinetic = kinetic;
}

void HexahedronSolver::advance_window(double t_end, const Eigen::Matrix3Xd* nodal_forces) {
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
  auto add_work = [&](const Eigen::Matrix3Xd& dx) {
    state_.energy.internal_work += 0.5 * state_.internal_force.cwiseProduct(dx).sum();
    state_.energy.hourglass_work += 0.5 * state_.hourglass_force.cwiseProduct(dx).sum();
    state_.energy.external_work += 0.5 * state_.external_force.cwiseProduct(dx).sum();
    state_.energy.contact_work -= 0.5 * state_.contact_force.cwiseProduct(dx).sum();
  };

  while (state_.time < t_end) {
    compute_external_force(state_.time, nodal_forces);
    a = (state_.external_force + state_.contact_force - state_.internal_force).array().rowwise() *
        inverse_mass.transpose();
    apply_constraints(a);
    double dt = contact_planes_.empty() ? state_.stable_step
                                        : state_.stable_step / std::sqrt(1.0 + options_.contact_stiffness_factor);
    const double remaining = t_end - state_.time;
    if (remaining <= dt) {
      dt = remaining;
    } else if (remaining < 2.0 * dt) {
      dt = 0.5 * remaining;
    }
    const double averaged_step = 0.5 * (state_.last_step + dt);
    if (alpha > 0.0) {
      previous_half_velocity_ = v_half;
      v_half = ((1.0 - 0.5 * alpha * averaged_step) * v_half + averaged_step * a) / (1.0 + 0.5 * alpha * averaged_step);
    } else {
      v_half += averaged_step * a;
    }
    apply_constraints(v_half);
    const Eigen::Matrix3Xd dx = dt * v_half;
    if (alpha > 0.0) {
      for (Eigen::Index i = 0; i < x.cols(); ++i) {
        state_.energy.damping_work +=
            alpha * model_.nodal_mass(i) * 0.5 * (v_half.col(i) + previous_half_velocity_.col(i)).dot(dx.col(i));
      }
    }
    add_work(dx);
    x += dx;
    state_.time = (dt == remaining) ? t_end : state_.time + dt;
    ++state_.step;
    state_.last_step = dt;

    compute_internal_force(state_.step % options_.time_step_update_interval == 0);
    compute_contact_force();
    compute_external_force(state_.time, nodal_forces);
    add_work(dx);
    a = (state_.external_force + state_.contact_force - state_.internal_force).array().rowwise() *
        inverse_mass.transpose();
    apply_constraints(a);
    state_.velocity = v_half + 0.5 * dt * a;
    update_kinetic_energy();
  }
}

void HexahedronSolver::element_fields(Eigen::VectorXd& max_principal_stress,
                                      Eigen::VectorXd& max_principal_log_strain) const {
  fields(max_principal_stress, max_principal_log_strain, false);
}

void HexahedronSolver::surface_fields(Eigen::VectorXd& max_principal_stress,
                                      Eigen::VectorXd& max_principal_log_strain) const {
  fields(max_principal_stress, max_principal_log_strain, true);
}

void HexahedronSolver::fields(Eigen::VectorXd& max_principal_stress, Eigen::VectorXd& max_principal_log_strain,
                              bool surfaces) const {
  // Centre: the 3D law at the F-bar F (the integration point). Surfaces: the centres of the faces
  // zeta = -1, +1, where the full trilinear gradient gives the in-plane C2 in the material frame,
  // evaluated with the sheet's plane-stress law (sigma33 = 0, as the shell's outer thickness points).
  static const std::array<Eigen::Matrix<double, 3, 8>, 2> faces{hex_shape_derivatives(Eigen::Vector3d(0, 0, -1)),
                                                                hex_shape_derivatives(Eigen::Vector3d(0, 0, 1))};
  const Material sheet = plane_stress_form(material_);
  const auto num_elements = static_cast<Eigen::Index>(model_.elements.size());
  max_principal_stress.resize(num_elements);
  max_principal_log_strain.resize(num_elements);
  std::visit(
      [&](const auto& law) {
#pragma omp parallel for schedule(static) if (num_elements >= kMinElementsForThreads)
        for (Eigen::Index e = 0; e < num_elements; ++e) {
          try {
            const HexElement& el = model_.elements[static_cast<std::size_t>(e)];
            const HexKinematics k = hex_kinematics(el, state_.position);
            Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
            eig.computeDirect(hex_cauchy_stress(el, law, k.F), Eigen::EigenvaluesOnly);
            double stress = eig.eigenvalues().maxCoeff();
            eig.computeDirect(k.F.transpose() * k.F, Eigen::EigenvaluesOnly);
            double strain = 0.5 * std::log(eig.eigenvalues().maxCoeff());
            if (!surfaces) {
              max_principal_stress(e) = stress;
              max_principal_log_strain(e) = strain;
              continue;
            }
            stress = strain = -std::numeric_limits<double>::infinity();
            Eigen::Matrix<double, 3, 8> X;
            for (int a = 0; a < 8; ++a) X.col(a) = model_.reference_positions.col(el.nodes[static_cast<std::size_t>(a)]);
            const Eigen::Matrix<double, 3, 2> in_plane = el.material_axes.leftCols<2>();
            for (const auto& dN : faces) {
              const Eigen::Matrix<double, 3, 8> gradient = (X * dN.transpose()).inverse().transpose() * dN;
              const Eigen::Matrix<double, 3, 2> F2 = k.x * gradient.transpose() * in_plane;
              const Eigen::Matrix2d C2 = F2.transpose() * F2;
              const PlaneStressResponse r = plane_stress(sheet, C2, false);
              // Cauchy stress F2 S F2^T / J shares its non-zero eigenvalues with S C2 / J, J = lambda3 sqrt(det C2).
              const Eigen::Matrix2d M = r.stress * C2 / (r.thickness_stretch * std::sqrt(C2.determinant()));
              const double half_trace = 0.5 * M.trace();
              stress = std::max(stress, half_trace + std::sqrt(std::max(0.0, half_trace * half_trace - M.determinant())));
              const double c_half = 0.5 * C2.trace();
              strain = std::max(strain, 0.5 * std::log(c_half + std::sqrt(std::max(0.0, c_half * c_half - C2.determinant()))));
            }
            max_principal_stress(e) = stress;
            max_principal_log_strain(e) = strain;
          } catch (const MaterialStateError&) {
            max_principal_stress(e) = std::numeric_limits<double>::quiet_NaN();
            max_principal_log_strain(e) = std::numeric_limits<double>::quiet_NaN();
          }
        }
      },
      material_);
}

}  // namespace valvefsi::solid
