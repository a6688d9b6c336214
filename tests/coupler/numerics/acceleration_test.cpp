// Acceleration on fixed points with known roots: convergence where theory says, and not elsewhere.
#include "valvefsi/coupling/acceleration.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <functional>
#include <iostream>
#include <stdexcept>
#include <string>

namespace valvefsi::coupling {
namespace {

using Operator = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;

struct Solve {
  bool converged = false;
  int evaluations = 0;  // of the operator, including the one that showed convergence
  Eigen::VectorXd root;
  double last_residual = 0.0;
};

// x_{k+1} = accelerate(x_k, H(x_k)) until the relative residual is below `tolerance`.
Solve iterate(Acceleration& acceleration, const Operator& h, Eigen::VectorXd x, double tolerance, int max_evaluations) {
  Solve s;
  acceleration.begin_window();
  for (s.evaluations = 1; s.evaluations <= max_evaluations; ++s.evaluations) {
    const Eigen::VectorXd hx = h(x);
    s.last_residual = relative_residual(x, hx);
    if (!std::isfinite(s.last_residual) || s.last_residual > 1e8) break;
    if (s.last_residual < tolerance) {
      s.converged = true;
      s.root = hx;
      acceleration.end_window();
      return s;
    }
    x = acceleration.next_input(x, hx);
  }
  s.root = x;
  return s;
}

AccelerationOptions options(AccelerationKind kind, double omega) {
  AccelerationOptions o;
  o.kind = kind;
  o.relaxation = omega;
  return o;
}

// A non-symmetric matrix with prescribed real eigenvalues: S diag(lambda) S^-1.
Eigen::MatrixXd with_eigenvalues(const Eigen::VectorXd& lambda) {
  const Eigen::Index n = lambda.size();
  Eigen::MatrixXd s(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < n; ++j) s(i, j) = (i == j ? 2.0 : 0.0) + std::sin(1.0 + 3.0 * double(i) + 7.0 * double(j)) * 0.6;
  }
  return s * lambda.asDiagonal() * s.inverse();
}

// H(x) = x* + A (x - x*) + 0.2 [ (x - x*)_1^2, (x - x*)_0 (x - x*)_2, sin((x - x*)_0)^2 ]: nonlinear, root x*.
struct NonlinearMap {
  Eigen::Vector3d root{1.0, -2.0, 0.5};
  Eigen::Matrix3d a;
  explicit NonlinearMap(const Eigen::Vector3d& eigenvalues) : a(with_eigenvalues(eigenvalues)) {}
  Eigen::VectorXd operator()(const Eigen::VectorXd& x) const {
    const Eigen::Vector3d e = x - root;
    const Eigen::Vector3d quadratic(e(1) * e(1), e(0) * e(2), std::sin(e(0)) * std::sin(e(0)));
    return root + a * e + 0.2 * quadratic;
  }
};

TEST(ConstantRelaxation, ConvergesExactlyInsideTheTheoreticalRange) {
  // Jacobian eigenvalues {-3, -1, 0.5}: |1 - omega (1 - lambda)| < 1 for all iff omega < 2/(1+3) = 0.5.
  const NonlinearMap h(Eigen::Vector3d(-3.0, -1.0, 0.5));
  const Eigen::VectorXd start = h.root + Eigen::Vector3d(1e-3, -2e-3, 1.5e-3);
  auto below = make_acceleration(options(AccelerationKind::constant_relaxation, 0.47));
  const Solve converged = iterate(*below, h, start, 1e-12, 2000);
  ASSERT_TRUE(converged.converged);
  EXPECT_LT((converged.root - h.root).norm(), 1e-10);
  std::cout << "[ constant ] omega = 0.47 (limit 0.5): " << converged.evaluations << " evaluations\n";

  auto above = make_acceleration(options(AccelerationKind::constant_relaxation, 0.53));
  const Solve diverged = iterate(*above, h, start, 1e-12, 2000);
  EXPECT_FALSE(diverged.converged);
}

TEST(Aitken, ConvergesWhereSomeConstantOmegaWouldAndFaster) {
  const NonlinearMap h(Eigen::Vector3d(-3.0, -1.0, 0.5));
  const Eigen::VectorXd start = h.root + Eigen::Vector3d(0.2, -0.3, 0.1);
  auto aitken = make_acceleration(options(AccelerationKind::aitken, 0.2));
  const Solve s = iterate(*aitken, h, start, 1e-10, 500);
  ASSERT_TRUE(s.converged);
  EXPECT_LT((s.root - h.root).norm(), 1e-8);
  auto constant = make_acceleration(options(AccelerationKind::constant_relaxation, 0.2));
  const Solve c = iterate(*constant, h, start, 1e-10, 2000);
  ASSERT_TRUE(c.converged);
  EXPECT_LT(s.evaluations, c.evaluations);
  std::cout << "[ aitken ] " << s.evaluations << " evaluations; constant omega = 0.2: " << c.evaluations << "\n";
}

TEST(IqnIls, ConvergesOnANonContractiveMapWhereNoConstantOmegaDoes) {
  // Eigenvalues {-3, 0.5, 1.8}: lambda > 1 needs omega < 0, lambda = -3 needs omega > 0.
  const NonlinearMap h(Eigen::Vector3d(-3.0, 0.5, 1.8));
  const Eigen::VectorXd start = h.root + Eigen::Vector3d(0.3, 0.2, -0.4);
  for (const double omega : {0.05, 0.2, 0.45, 1.0}) {
    auto constant = make_acceleration(options(AccelerationKind::constant_relaxation, omega));
    EXPECT_FALSE(iterate(*constant, h, start, 1e-10, 3000).converged) << "omega " << omega;
  }
  auto iqn = make_acceleration(options(AccelerationKind::iqn_ils, 0.1));
  const Solve s = iterate(*iqn, h, start, 1e-12, 25);
  ASSERT_TRUE(s.converged) << "residual " << s.last_residual;
  EXPECT_LE(s.evaluations, 15);
  std::cout << "[ iqn-ils ] non-contractive 3D map: " << s.evaluations << " evaluations\n";
  EXPECT_LT((s.root - h.root).norm(), 1e-10);
}

TEST(IqnIls, SolvesALinearProblemOfDimensionNInNPlusOneUpdates) {
  // For affine H, IQN-ILS is a Krylov method: after n+1 updates the input is the root.
  const int n = 7;
  Eigen::VectorXd lambda(n);
  lambda << -4.0, -1.5, -0.3, 0.2, 0.7, 1.4, 2.5;
  const Eigen::MatrixXd a = with_eigenvalues(lambda);
  const Eigen::VectorXd root = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
  const auto h = [&](const Eigen::VectorXd& x) -> Eigen::VectorXd { return root + a * (x - root); };
  auto iqn = make_acceleration(options(AccelerationKind::iqn_ils, 0.3));
  iqn->begin_window();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  for (int update = 1; update <= n + 1; ++update) {
    const Eigen::VectorXd hx = h(x);
    x = iqn->next_input(x, hx);
    if (update < n) {
      EXPECT_GT((x - root).norm(), 1e-6) << "update " << update;  // not earlier by accident
    }
  }
  EXPECT_LT((x - root).norm(), 1e-9 * root.norm());
}

TEST(IqnIls, ReusingPastWindowsSolvesTheNextWindowInOneUpdate) {
  // Same Jacobian, a new root every window (as between time steps): with reuse the columns
  // of earlier windows already span the space, without reuse every window starts afresh.
  const int n = 6;
  Eigen::VectorXd lambda(n);
  lambda << -3.0, -1.0, -0.2, 0.4, 1.3, 2.0;
  const Eigen::MatrixXd a = with_eigenvalues(lambda);
  AccelerationOptions reuse = options(AccelerationKind::iqn_ils, 0.3);
  reuse.reused_windows = 3;
  auto with_reuse = make_acceleration(reuse);
  auto without_reuse = make_acceleration(options(AccelerationKind::iqn_ils, 0.3));
  for (int window = 0; window < 4; ++window) {
    const Eigen::VectorXd root = Eigen::VectorXd::Constant(n, 0.1 * window) + Eigen::VectorXd::LinSpaced(n, 0.0, 1.0);
    const auto h = [&](const Eigen::VectorXd& x) -> Eigen::VectorXd { return root + a * (x - root); };
    const Eigen::VectorXd start = Eigen::VectorXd::Zero(n);
    const Solve reused = iterate(*with_reuse, h, start, 1e-10, 50);
    const Solve fresh = iterate(*without_reuse, h, start, 1e-10, 50);
    ASSERT_TRUE(reused.converged && fresh.converged);
    EXPECT_LT((reused.root - root).norm(), 1e-8);
    EXPECT_GE(fresh.evaluations, n + 1) << "window " << window;  // a fresh Krylov space needs ~n columns
    if (window > 0) {
      EXPECT_LE(reused.evaluations, 2) << "window " << window;
    }
    std::cout << "[ iqn-ils ] window " << window << ": " << reused.evaluations << " evaluations with reuse, "
              << fresh.evaluations << " without\n";
  }
}

TEST(IqnIls, RepeatedDataIsFilteredInsteadOfProducingNaN) {
  AccelerationOptions o = options(AccelerationKind::iqn_ils, 0.5);
  auto iqn = make_acceleration(o);
  iqn->begin_window();
  const Eigen::VectorXd x = Eigen::VectorXd::Constant(4, 1.0);
  const Eigen::VectorXd hx = Eigen::VectorXd::Constant(4, 2.0);
  const Eigen::VectorXd first = iqn->next_input(x, hx);
  const Eigen::VectorXd second = iqn->next_input(x, hx);  // zero difference column
  EXPECT_TRUE(first.allFinite() && second.allFinite());
  EXPECT_LT((second - (x + 0.5 * (hx - x))).norm(), 1e-15);
}

TEST(AccelerationParse, NamesAndErrors) {
  EXPECT_EQ(parse_acceleration_kind("constant"), AccelerationKind::constant_relaxation);
  EXPECT_EQ(parse_acceleration_kind("aitken"), AccelerationKind::aitken);
  EXPECT_EQ(parse_acceleration_kind("iqn-ils"), AccelerationKind::iqn_ils);
  try {
    parse_acceleration_kind("anderson");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("iqn-ils"), std::string::npos) << e.what();
  }
  AccelerationOptions bad;
  bad.relaxation = 0.0;
  EXPECT_THROW(make_acceleration(bad), std::invalid_argument);
  bad = AccelerationOptions{};
  bad.max_columns = 0;
  EXPECT_THROW(make_acceleration(bad), std::invalid_argument);
  auto iqn = make_acceleration(AccelerationOptions{});
  EXPECT_THROW(iqn->next_input(Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(4)), std::invalid_argument);
}

TEST(RelativeResidual, IsTheNormOfTheChangeOverTheNormOfTheOutput) {
  EXPECT_DOUBLE_EQ(relative_residual(Eigen::Vector2d(3.0, 0.0), Eigen::Vector2d(0.0, 4.0)), 5.0 / 4.0);
  EXPECT_EQ(relative_residual(Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()), 0.0);
}

}  // namespace
}  // namespace valvefsi::coupling
