#pragma once
// The polynomial part of an RBF interpolant: 1 and the linear terms along the principal
// directions in which the nodes spread. A flat surface (or a 2D interface, z = 0) has no
// extent along its normal, and a term there would make the Schur complement singular.

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include <cmath>
#include <vector>

namespace valvefsi::coupling::detail {

struct RbfPolynomial {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Matrix3Xd axes = Eigen::Matrix3Xd(3, 0);  // kept directions, scaled by 1 / standard deviation

  static RbfPolynomial fit(const Eigen::Matrix3Xd& nodes, bool linear) {
    RbfPolynomial p;
    p.origin = nodes.rowwise().mean();
    if (!linear || nodes.cols() < 2) return p;
    const Eigen::Matrix3Xd centred = nodes.colwise() - p.origin;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> spread(centred * centred.transpose() /
                                                                static_cast<double>(nodes.cols()));
    const double largest = spread.eigenvalues().maxCoeff();
    std::vector<Eigen::Vector3d> kept;
    for (int k = 0; k < 3; ++k) {
      const double variance = spread.eigenvalues()(k);
      // Thinner than 1e-5 of the largest extent is flat: the variance there is round-off.
      if (largest > 0.0 && variance > 1e-10 * largest) kept.push_back(spread.eigenvectors().col(k) / std::sqrt(variance));
    }
    p.axes.resize(3, static_cast<Eigen::Index>(kept.size()));
    for (std::size_t k = 0; k < kept.size(); ++k) p.axes.col(static_cast<Eigen::Index>(k)) = kept[k];
    return p;
  }

  Eigen::Index terms() const { return 1 + axes.cols(); }

  // One row per column of x: [1, linear terms].
  Eigen::MatrixXd at(const Eigen::Matrix3Xd& x) const {
    Eigen::MatrixXd values(x.cols(), terms());
    values.col(0).setOnes();
    values.rightCols(axes.cols()) = (x.colwise() - origin).transpose() * axes;
    return values;
  }
};

}  // namespace valvefsi::coupling::detail
