#pragma once
// Compact-support RBF interpolation (Wendland C2) with a linear polynomial, in saddle-point form
//   [Phi P; P^T 0] [gamma; beta] = [f; 0],   u(x) = sum_j gamma_j phi(|x - x_j|) + p(x) beta,
// solved by a sparse Cholesky (LDL^T) of Phi and the small Schur complement S = P^T Phi^-1 P.
// Consistent: u_points = E_phi gamma + E_p beta. Conservative: f_nodes = H^T f_points with the
// same factorisation (H = E_phi Phi^-1 (I - P S^-1 Q^T) + E_p S^-1 Q^T, Q = Phi^-1 P).

#include "valvefsi/coupling/interface_mapping.hpp"

#include "rbf_polynomial.hpp"

#include <Eigen/Cholesky>
#include <Eigen/SparseCholesky>

#include <mutex>

namespace valvefsi::coupling::detail {

// Wendland's C2 function, positive definite in up to three dimensions.
inline double wendland_c2(double r_over_support) {
  if (r_over_support >= 1.0) return 0.0;
  const double s = 1.0 - r_over_support;
  return s * s * s * s * (4.0 * r_over_support + 1.0);
}

class RadialBasisSystem {
 public:
  RadialBasisSystem(const Eigen::Matrix3Xd& nodes, const Eigen::Matrix3Xd& points, double support_radius,
                    bool linear_polynomial);
  Eigen::MatrixX3d consistent(const Eigen::MatrixX3d& values_at_nodes) const;   // n_nodes x 3 -> n_points x 3
  Eigen::MatrixX3d conservative(const Eigen::MatrixX3d& forces_at_points) const; // n_points x 3 -> n_nodes x 3
  const Eigen::SparseMatrix<double, Eigen::RowMajor>& assembled_matrix() const;  // dense H, built on first call
  Eigen::Index point_count() const { return evaluation_.rows(); }
  Eigen::Index node_count() const { return evaluation_.cols(); }
  Eigen::Index polynomial_terms() const { return node_polynomial_.cols(); }

 private:
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> phi_factor_;
  Eigen::SparseMatrix<double, Eigen::RowMajor> evaluation_;  // E_phi: phi(|x_i - x_j|), points x nodes
  RbfPolynomial polynomial_;
  Eigen::MatrixXd node_polynomial_;   // P, nodes x terms
  Eigen::MatrixXd point_polynomial_;  // E_p, points x terms
  Eigen::MatrixXd phi_inverse_p_;     // Q = Phi^-1 P
  Eigen::LLT<Eigen::MatrixXd> schur_factor_;

  mutable std::once_flag assembled_once_;
  mutable Eigen::SparseMatrix<double, Eigen::RowMajor> assembled_;
};

}  // namespace valvefsi::coupling::detail
