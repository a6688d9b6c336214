#include "radial_basis_system.hpp"

#include "point_cloud_tree.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace valvefsi::coupling::detail {

namespace {

// phi(|a_i - b_j|) for all pairs closer than the support radius.
template <int Order>
Eigen::SparseMatrix<double, Order> kernel_matrix(const Eigen::Matrix3Xd& rows, const PointCloudTree& column_tree,
                                                 Eigen::Index column_count, double support_radius) {
  std::vector<Eigen::Triplet<double>> entries;
  std::vector<std::pair<std::uint32_t, double>> found;
  for (Eigen::Index i = 0; i < rows.cols(); ++i) {
    column_tree.within(rows.col(i), support_radius, found);
    for (const auto& [j, distance_squared] : found) {
      const double value = wendland_c2(std::sqrt(distance_squared) / support_radius);
      if (value > 0.0) entries.emplace_back(i, static_cast<Eigen::Index>(j), value);
    }
  }
  Eigen::SparseMatrix<double, Order> matrix(rows.cols(), column_count);
  matrix.setFromTriplets(entries.begin(), entries.end());
  return matrix;
}

}  // namespace

RadialBasisSystem::RadialBasisSystem(const Eigen::Matrix3Xd& nodes, const Eigen::Matrix3Xd& points,
                                     double support_radius, bool linear_polynomial) {
  const PointCloudTree node_tree(nodes);
  const auto phi = kernel_matrix<Eigen::ColMajor>(nodes, node_tree, nodes.cols(), support_radius);
  evaluation_ = kernel_matrix<Eigen::RowMajor>(points, node_tree, nodes.cols(), support_radius);
  phi_factor_.compute(phi);
  if (phi_factor_.info() != Eigen::Success) {
    throw std::runtime_error("radial-basis mapping: the RBF matrix of the " + std::to_string(nodes.cols()) +
                             " interface nodes could not be factorised (support radius " +
                             std::to_string(support_radius) + " m); check for duplicate nodes");
  }

  polynomial_ = RbfPolynomial::fit(nodes, linear_polynomial);
  node_polynomial_ = polynomial_.at(nodes);
  point_polynomial_ = polynomial_.at(points);
  phi_inverse_p_ = phi_factor_.solve(node_polynomial_);
  schur_factor_.compute(node_polynomial_.transpose() * phi_inverse_p_);
  if (schur_factor_.info() != Eigen::Success) {
    throw std::runtime_error("radial-basis mapping: the polynomial part is singular for these " +
                             std::to_string(nodes.cols()) + " interface nodes");
  }
}

Eigen::MatrixX3d RadialBasisSystem::consistent(const Eigen::MatrixX3d& values_at_nodes) const {
  const Eigen::MatrixX3d c = phi_factor_.solve(values_at_nodes);
  const Eigen::MatrixXd beta = schur_factor_.solve(node_polynomial_.transpose() * c);
  const Eigen::MatrixX3d gamma = c - phi_inverse_p_ * beta;
  return evaluation_ * gamma + point_polynomial_ * beta;
}

Eigen::MatrixX3d RadialBasisSystem::conservative(const Eigen::MatrixX3d& forces_at_points) const {
  const Eigen::MatrixX3d a = phi_factor_.solve(Eigen::MatrixX3d(evaluation_.transpose() * forces_at_points));
  const Eigen::MatrixXd b =
      schur_factor_.solve(point_polynomial_.transpose() * forces_at_points - node_polynomial_.transpose() * a);
  return a + phi_inverse_p_ * b;
}

const Eigen::SparseMatrix<double, Eigen::RowMajor>& RadialBasisSystem::assembled_matrix() const {
  std::call_once(assembled_once_, [this] {
    constexpr double largest_dense_entries = 5e7;  // 400 MB of doubles
    if (static_cast<double>(point_count()) * static_cast<double>(node_count()) > largest_dense_entries) {
      throw std::logic_error("radial-basis mapping: H is dense (" + std::to_string(point_count()) + " x " +
                             std::to_string(node_count()) +
                             "); use map_consistent/map_conservative instead of matrix() at this size");
    }
    // H^T = conservative(I) column block by column block, three points at a time.
    Eigen::MatrixXd h(point_count(), node_count());
    for (Eigen::Index i = 0; i < point_count(); i += 3) {
      const Eigen::Index width = std::min<Eigen::Index>(3, point_count() - i);
      Eigen::MatrixX3d unit = Eigen::MatrixX3d::Zero(point_count(), 3);
      for (Eigen::Index k = 0; k < width; ++k) unit(i + k, k) = 1.0;
      h.middleRows(i, width) = conservative(unit).leftCols(width).transpose();
    }
    assembled_ = h.sparseView(0.0, 0.0);
  });
  return assembled_;
}

}  // namespace valvefsi::coupling::detail
