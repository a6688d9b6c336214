#include "valvefsi/coupling/model_problems/nonlinear_fixed_point.hpp"

#include "parameter_checks.hpp"

#include <Eigen/Dense>

namespace valvefsi::coupling::model {

NonlinearFixedPoint NonlinearFixedPoint::standard() {
  NonlinearFixedPoint p;
  p.root = Eigen::Vector3d(0.4, -0.3, 0.8);
  p.b.resize(3, 3);
  p.b << 1.0, 0.2, -0.1, 0.3, 0.8, 0.2, -0.2, 0.1, 1.2;
  // Choose A so that dH/dx(x*) = M diag(-2.5, 0.3, 1.6) M^-1: one eigenvalue beyond each side of +-1.
  Eigen::Matrix3d m;
  m << 1.0, 0.4, -0.3, 0.2, 1.0, 0.5, -0.4, 0.3, 1.0;
  const Eigen::Matrix3d target = m * Eigen::Vector3d(-2.5, 0.3, 1.6).asDiagonal() * m.inverse();
  const Eigen::VectorXd sech2 = 1.0 - p.root.array().tanh().square();
  const Eigen::Matrix3d db = p.b + 0.5 * Eigen::MatrixXd(sech2.asDiagonal());
  p.a = target * db.inverse();
  return p;
}

Eigen::VectorXd NonlinearFixedPoint::fluid(const Eigen::VectorXd& x) const {
  return b * x + 0.5 * x.array().tanh().matrix();
}

Eigen::VectorXd NonlinearFixedPoint::solid(const Eigen::VectorXd& y) const {
  return root + a * (y - fluid(root));
}

Eigen::MatrixXd NonlinearFixedPoint::jacobian_at_root() const {
  const Eigen::VectorXd sech2 = 1.0 - root.array().tanh().square();
  return a * (b + 0.5 * Eigen::MatrixXd(sech2.asDiagonal()));
}

Eigen::VectorXd NonlinearFixedPointFluid::advance(double window, const Eigen::VectorXd& x) {
  require_size("nonlinear fixed point fluid", "motion", x, problem_.root.size());
  time_ += window;
  return problem_.fluid(x);
}

Eigen::VectorXd NonlinearFixedPointSolid::advance(double window, const Eigen::VectorXd& y) {
  require_size("nonlinear fixed point solid", "loads", y, problem_.root.size());
  time_ += window;
  return problem_.solid(y);
}

}  // namespace valvefsi::coupling::model
