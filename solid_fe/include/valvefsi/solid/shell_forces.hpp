#pragma once
// Internal forces of the rotation-free shell triangle (docs/solid_fe.md, "Shell element").
// Per element: F = sum_a x_a (x) dN_a/dX, C_m = F^T F; curvature change kappa from the fold
// angles of its three edges; at each Gauss point z through the thickness C(z) = C_m + 2 z kappa
// (Kirchhoff), S(z) from the plane-stress material; N = int S dz, M = int z S dz;
//   f_a = A0 F N dN_a   (membrane)   +   A0 sum_i (B^-T M)_i d theta_i / d x   (bending).
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "valvefsi/solid/hinge_angle.hpp"
#include "valvefsi/solid/material.hpp"
#include "valvefsi/solid/material_error.hpp"
#include "valvefsi/solid/shell_model.hpp"

namespace valvefsi::solid {

// Wave-speed factor of the bending part in the element's highest frequency,
// omega^2 = (2 c / L)^2 (1 + kBendingFrequencyFactor (h / L)^2); checked against the true
// highest frequency of small meshes in tests/solid_fe/shell_stability_test.cpp.
inline constexpr double kBendingFrequencyFactor = 0.5;

struct ElementState {
  Eigen::Matrix<double, 3, 2> deformation_gradient;  // F of the mid-surface (3x2)
  Eigen::Matrix2d membrane_c;                        // C_m
  Eigen::Matrix2d curvature;                         // kappa (2x2, reference frame)
  Eigen::Vector3d fold_angle_change;                 // theta_i - theta0_i per edge slot
  std::array<HingeSide, 3> own_side;
  std::array<HingeSide, 3> neighbour_side;
};

// Each triangle's own hinge sides (3 per element, slot i about edge i) at x, for all elements:
// an interior edge's two sides are then computed once per step, not once by each of its triangles.
inline void own_hinge_sides(const ShellModel& model, std::int64_t e, const Eigen::Matrix3Xd& x, HingeSide* sides) {
  const ShellElement& el = model.elements[static_cast<std::size_t>(e)];
  for (int i = 0; i < 3; ++i) {
    if (el.edge_kind[i] == EdgeKind::free) continue;
    sides[3 * e + i] = hinge_side(x.col(el.nodes[(i + 1) % 3]), x.col(el.nodes[(i + 2) % 3]), x.col(el.nodes[i]), false);
  }
}

// `sides`: all elements' own hinge sides at x (own_hinge_sides), or nullptr to compute them here.
inline ElementState element_kinematics(const ShellModel& model, const ShellElement& el, const Eigen::Matrix3Xd& x,
                                       const HingeSide* sides = nullptr, std::int64_t index = -1) {
  ElementState s;
  s.deformation_gradient.setZero();
  for (int a = 0; a < 3; ++a) {
    s.deformation_gradient += x.col(el.nodes[a]) * el.shape_gradients.row(a);
  }
  s.membrane_c = s.deformation_gradient.transpose() * s.deformation_gradient;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d& xa = x.col(el.nodes[(i + 1) % 3]);
    const Eigen::Vector3d& xb = x.col(el.nodes[(i + 2) % 3]);
    switch (el.edge_kind[i]) {
      case EdgeKind::interior: {
        if (sides != nullptr) {
          s.own_side[i] = sides[3 * index + i];
          // The neighbour's own side about the same edge runs b -> a: swap its start and end.
          const HingeSide& other = sides[3 * static_cast<std::int64_t>(el.neighbour[i]) + el.neighbour_slot[i]];
          s.neighbour_side[i] = {other.unit_normal, other.grad_opposite, other.grad_end, other.grad_start};
        } else {
          s.own_side[i] = hinge_side(xa, xb, x.col(el.nodes[i]), false);
          s.neighbour_side[i] = hinge_side(xa, xb, x.col(el.opposite[i]), true);
        }
        s.fold_angle_change(i) = fold_angle(s.own_side[i], s.neighbour_side[i], xa, xb) -
                                 el.reference_fold_angle[i];
        break;
      }
      case EdgeKind::mirror: {
        const Plane& plane = model.mirror_planes[static_cast<std::size_t>(el.mirror_plane[i])];
        const Eigen::Vector3d xo = x.col(el.nodes[i]);
        const Eigen::Vector3d ghost = xo - 2.0 * (xo - plane.point).dot(plane.normal) * plane.normal;
        s.own_side[i] = sides != nullptr ? sides[3 * index + i] : hinge_side(xa, xb, xo, false);
        s.neighbour_side[i] = hinge_side(xa, xb, ghost, true);
        s.fold_angle_change(i) = fold_angle(s.own_side[i], s.neighbour_side[i], xa, xb) -
                                 el.reference_fold_angle[i];
        break;
      }
      case EdgeKind::clamped: {
        s.own_side[i] = sides != nullptr ? sides[3 * index + i] : hinge_side(xa, xb, x.col(el.nodes[i]), false);
        s.fold_angle_change(i) = clamped_angle(s.own_side[i], el.reference_normal, xa, xb);
        break;
      }
      case EdgeKind::free:
        s.fold_angle_change(i) = 0.0;
        break;
    }
  }
  const Eigen::Vector3d k = el.curvature_from_angles * s.fold_angle_change;
  s.curvature << k(0), 0.5 * k(2), 0.5 * k(2), k(1);
  return s;
}

// Largest eigenvalue of a symmetric 2x2 matrix.
inline double max_eigenvalue(const Eigen::Matrix2d& A) {
  const double mean = 0.5 * (A(0, 0) + A(1, 1));
  return mean + std::hypot(0.5 * (A(0, 0) - A(1, 1)), 0.5 * (A(0, 1) + A(1, 0)));
}

// Reference-frame wave modulus of one material point: the material part scaled by the stretch
// plus the stress part. The material part is bounded by the largest Gershgorin row sum of the
// tangent in Mandel form (an upper bound of its largest eigenvalue, cheaper than an eigen-solve).
inline double wave_modulus(const PlaneStressResponse& r, const Eigen::Matrix2d& C) {
  const Eigen::Matrix3d& D = r.tangent;
  const double s2 = std::sqrt(2.0);
  const double material = std::max({std::abs(D(0, 0)) + std::abs(D(0, 1)) + s2 * std::abs(D(0, 2)),
                                    std::abs(D(1, 0)) + std::abs(D(1, 1)) + s2 * std::abs(D(1, 2)),
                                    s2 * std::abs(D(2, 0)) + s2 * std::abs(D(2, 1)) + 2.0 * std::abs(D(2, 2))});
  return max_eigenvalue(C) * material + std::max(0.0, max_eigenvalue(r.stress));
}

// Stable explicit step of one element from its membrane modulus (thickness average of the
// wave modulus) and bending modulus (its z^2-weighted average), both in Pa.
inline double element_stable_step(const ShellElement& el, double membrane_modulus, double bending_modulus,
                                  double density) {
  const double ratio = el.thickness / el.min_height;
  const double omega2 = 4.0 / (el.min_height * el.min_height) / density *
                        (membrane_modulus + kBendingFrequencyFactor * ratio * ratio * bending_modulus);
  return omega2 > 0.0 ? 2.0 / std::sqrt(omega2) : std::numeric_limits<double>::infinity();
}

struct ElementResult {
  double strain_energy = 0;  // hyperelastic energy of the element (J)
  double stable_step = std::numeric_limits<double>::infinity();
};

// Adds the element's internal force to `forces` (3 x nodes).
template <class Law>
ElementResult add_element_internal_force(const ShellModel& model, const ShellElement& el, const Law& law,
                                         const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& forces,
                                         bool estimate_step, const HingeSide* sides = nullptr,
                                         std::int64_t index = -1) {
  const ElementState s = element_kinematics(model, el, x, sides, index);
  ElementResult result;
  Eigen::Matrix2d N = Eigen::Matrix2d::Zero(), M = Eigen::Matrix2d::Zero();
  const double half_thickness = 0.5 * el.thickness;
  double energy_per_area = 0.0;
  // Membrane modes feel the thickness average of the stiffness, bending modes its z^2 moment.
  double membrane_modulus = 0.0, bending_modulus = 0.0;
  for (int k = 0; k < model.thickness_points; ++k) {
    const double z = half_thickness * model.gauss_points[k];
    const double w = half_thickness * model.gauss_weights[k];
    const Eigen::Matrix2d C = s.membrane_c + 2.0 * z * s.curvature;
    const PlaneStressResponse r = law.plane_stress(C, estimate_step);
    N += w * r.stress;
    M += (w * z) * r.stress;
    energy_per_area += w * r.energy;
    if (estimate_step) {
      const double modulus = wave_modulus(r, C);
      membrane_modulus += w * modulus / el.thickness;
      bending_modulus += w * z * z * modulus * 12.0 / (el.thickness * el.thickness * el.thickness);
    }
  }
  if (estimate_step) {
    result.stable_step = element_stable_step(el, membrane_modulus, bending_modulus, model.density);
  }
  result.strain_energy = el.area * energy_per_area;

  const Eigen::Matrix<double, 3, 2> FN = s.deformation_gradient * N;
  for (int a = 0; a < 3; ++a) {
    forces.col(el.nodes[a]).noalias() += el.area * (FN * el.shape_gradients.row(a).transpose());
  }
  const Eigen::Vector3d m_voigt{M(0, 0), M(1, 1), M(0, 1)};
  const Eigen::Vector3d g = el.area * (el.curvature_from_angles.transpose() * m_voigt);
  for (int i = 0; i < 3; ++i) {
    if (el.edge_kind[i] == EdgeKind::free || g(i) == 0.0) continue;
    const int ia = el.nodes[(i + 1) % 3], ib = el.nodes[(i + 2) % 3];
    const HingeSide& own = s.own_side[i];
    forces.col(el.nodes[i]) += g(i) * own.grad_opposite;
    forces.col(ia) += g(i) * own.grad_start;
    forces.col(ib) += g(i) * own.grad_end;
    if (el.edge_kind[i] == EdgeKind::interior) {
      const HingeSide& other = s.neighbour_side[i];
      forces.col(el.opposite[i]) += g(i) * other.grad_opposite;
      forces.col(ia) += g(i) * other.grad_start;
      forces.col(ib) += g(i) * other.grad_end;
    } else if (el.edge_kind[i] == EdgeKind::mirror) {
      // The ghost vertex is the reflection R x_i (R = I - 2 n n): chain rule through R.
      const HingeSide& other = s.neighbour_side[i];
      const Eigen::Vector3d& n = model.mirror_planes[static_cast<std::size_t>(el.mirror_plane[i])].normal;
      const Eigen::Vector3d& d = other.grad_opposite;
      forces.col(el.nodes[i]) += g(i) * (d - 2.0 * n.dot(d) * n);
      forces.col(ia) += g(i) * other.grad_start;
      forces.col(ib) += g(i) * other.grad_end;
    }
  }
  return result;
}

// Per-element results for output: maximum principal Cauchy stress and logarithmic strain
// over the thickness points.
struct ElementFieldValues {
  double max_principal_stress = 0;  // Pa
  double max_principal_log_strain = 0;
};

template <class Law>
ElementFieldValues element_field_values(const ShellModel& model, const ShellElement& el, const Law& law,
                                        const Eigen::Matrix3Xd& x) {
  const ElementState s = element_kinematics(model, el, x);
  ElementFieldValues out;
  out.max_principal_stress = -std::numeric_limits<double>::infinity();
  out.max_principal_log_strain = -std::numeric_limits<double>::infinity();
  for (int k = 0; k < model.thickness_points; ++k) {
    const double z = 0.5 * el.thickness * model.gauss_points[k];
    const Eigen::Matrix2d C = s.membrane_c + 2.0 * z * s.curvature;
    const PlaneStressResponse r = law.plane_stress(C, false);
    // Cauchy stress sigma = F S F^T / J has the non-zero eigenvalues of S C / J.
    const double J = r.thickness_stretch * std::sqrt(C.determinant());
    const Eigen::Matrix2d SC = r.stress * C / J;
    const double tr = SC.trace(), det = SC.determinant();
    const double sigma_max = 0.5 * tr + std::sqrt(std::max(0.25 * tr * tr - det, 0.0));
    out.max_principal_stress = std::max(out.max_principal_stress, sigma_max);
    out.max_principal_log_strain = std::max(out.max_principal_log_strain, 0.5 * std::log(max_eigenvalue(C)));
  }
  return out;
}

}  // namespace valvefsi::solid
