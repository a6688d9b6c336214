#pragma once
// Generalized-alpha (Chung & Hulbert 1993) as the implicit integrator uses it
// (implicit_dynamics.cpp): its parameters and its energy identity, which the ledger books
// (docs/solid_fe.md, "Seventeenth session (b): a ledger for generalized-alpha").
#include <Eigen/Core>

namespace valvefsi::solid {

struct GeneralizedAlphaParameters {
  double alpha_m = 0, alpha_f = 0, gamma = 0, beta = 0;
};

// Chung & Hulbert's optimal set for a spectral radius rho_inf at infinite frequency.
inline GeneralizedAlphaParameters generalized_alpha_parameters(double rho_inf) {
  GeneralizedAlphaParameters p;
  p.alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
  p.alpha_f = rho_inf / (rho_inf + 1.0);
  p.gamma = 0.5 - p.alpha_m + p.alpha_f;
  p.beta = 0.25 * (1.0 - p.alpha_m + p.alpha_f) * (1.0 - p.alpha_m + p.alpha_f);
  return p;
}

// Energy the scheme removes over one step of size h (J; negative: it creates energy), from the
// step's own quantities. With the imbalance of the instantaneous equation of motion at each end,
// e = M a + c M v - F (F = external + contact - internal, c the mass damping), s = alpha_f -
// alpha_m, and the Newmark updates, the step's equation dotted with its increment dx gives
//   dx . r = dKE + W_damping - W_net + D,
//   D = (1/2 - alpha_f) dx . (e_end - e_start) + s^2 h^2 / 8 d(a . M a) + s^3 h^2 / 4 da . M da,
// with r the step's residual M a_m + c M v_f - F_f (zero at convergence) and the works
// trapezoidal, as the explicit ledger books them. D is exact for nonlinear forces too; it is 0 for
// rho_inf = 1 (alpha_f = alpha_m = 1/2). Constrained nodes: dx, a and v satisfy the constraints,
// so the reactions do no work.
inline double generalized_alpha_dissipation(const GeneralizedAlphaParameters& p, double h,
                                            const Eigen::VectorXd& nodal_mass, const Eigen::Matrix3Xd& dx,
                                            const Eigen::Matrix3Xd& a_start, const Eigen::Matrix3Xd& a_end,
                                            const Eigen::Matrix3Xd& imbalance_start,
                                            const Eigen::Matrix3Xd& imbalance_end) {
  const double s = p.alpha_f - p.alpha_m;
  double imbalance_work = 0.0, acceleration_energy_change = 0.0, acceleration_jump = 0.0;
  for (Eigen::Index i = 0; i < dx.cols(); ++i) {
    imbalance_work += dx.col(i).dot(imbalance_end.col(i) - imbalance_start.col(i));
    const double m = nodal_mass(i);
    acceleration_energy_change += m * (a_end.col(i).squaredNorm() - a_start.col(i).squaredNorm());
    acceleration_jump += m * (a_end.col(i) - a_start.col(i)).squaredNorm();
  }
  return (0.5 - p.alpha_f) * imbalance_work + s * s * h * h / 8.0 * acceleration_energy_change +
         s * s * s * h * h / 4.0 * acceleration_jump;
}

}  // namespace valvefsi::solid
