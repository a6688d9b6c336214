#pragma once
// Incompressible Ogden solid in the reference's form (eq. 7):
//   W = sum_p 2 mu_p / a_p^2 (l1^a_p + l2^a_p + l3^a_p - 3)
// In plane stress l3 = 1/(l1 l2). Written in the eigenvalues c_i = l_i^2 of C2:
//   dW/dC2 = sum_i W_i N_i N_i,   W_i = dW/dc_i,
//   d2W/dC2 dC2 = sum_ij W_ij N_i N_i (x) N_j N_j + 1/2 (W_1 - W_2)/(c_1 - c_2) P (x) P,
// P = N_1 N_2 + N_2 N_1; for c_1 -> c_2 the quotient tends to W_11 - W_12.
#include <array>
#include <cmath>
#include <string>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "valvefsi/solid/invariant_plane_stress.hpp"
#include "valvefsi/solid/material_error.hpp"

namespace valvefsi::solid {

struct OgdenParameters {
  std::array<double, 2> mu_Pa{19.58e3, 260.56e3};  // mu_p
  std::array<double, 2> alpha{67.74, 27.47};         // a_p (dimensionless)
};

class Ogden {
 public:
  explicit Ogden(const OgdenParameters& p = {}) : p_(p) {}

  const OgdenParameters& parameters() const { return p_; }
  // Small-strain shear modulus of this form is sum mu_p; the sheet's in-plane modulus is 4x.
  double initial_membrane_modulus() const { return 4.0 * (p_.mu_Pa[0] + p_.mu_Pa[1]); }

  PlaneStressResponse plane_stress(const Eigen::Matrix2d& C, bool with_tangent = true) const {
    // Closed-form eigen-decomposition of the symmetric 2x2 C.
    const double mean = 0.5 * (C(0, 0) + C(1, 1));
    const double half_diff = 0.5 * (C(0, 0) - C(1, 1));
    const double radius = std::hypot(half_diff, C(0, 1));
    const double c1 = mean + radius, c2 = mean - radius;
    if (!(c2 > 0.0)) {
      throw MaterialStateError(fmt::format(
          "Ogden: in-plane C has eigenvalue {:g} <= 0 (element inverted or degenerate)", c2));
    }
    Eigen::Vector2d n1;
    if (radius > 0.0) {
      // Eigenvector of the larger eigenvalue: angle phi with tan(2 phi) = 2 C12 / (C11 - C22).
      const double phi = 0.5 * std::atan2(C(0, 1), half_diff);
      n1 = {std::cos(phi), std::sin(phi)};
    } else {
      n1 = Eigen::Vector2d::UnitX();
    }
    const Eigen::Vector2d n2{-n1(1), n1(0)};

    const double log_c1 = std::log(c1), log_c2 = std::log(c2);
    double W = 0, W1 = 0, W2 = 0, W11 = 0, W22 = 0, W12 = 0;
    for (int p = 0; p < 2; ++p) {
      const double a = p_.alpha[p], h = 0.5 * a;
      const double m = 2.0 * p_.mu_Pa[p] / (a * a);
      const double log_l3_power = -h * (log_c1 + log_c2);  // log of l3^a
      const double largest = std::max({h * log_c1, h * log_c2, log_l3_power});
      if (largest > kMaxExpArgument) {
        throw MaterialStateError(fmt::format(
            "Ogden: stretch power overflows (term {}: a = {:g}) at l1 = {:g}, l2 = {:g}, l3 = {:g}",
            p + 1, a, std::sqrt(c1), std::sqrt(c2), 1.0 / std::sqrt(c1 * c2)));
      }
      const double p1 = std::exp(h * log_c1);  // c1^(a/2) = l1^a
      const double p2 = std::exp(h * log_c2);
      const double p3 = std::exp(log_l3_power);  // (c1 c2)^(-a/2) = l3^a
      W += m * (p1 + p2 + p3 - 3.0);
      W1 += m * h * (p1 - p3) / c1;
      W2 += m * h * (p2 - p3) / c2;
      W11 += m * h * ((h - 1.0) * p1 + (h + 1.0) * p3) / (c1 * c1);
      W22 += m * h * ((h - 1.0) * p2 + (h + 1.0) * p3) / (c2 * c2);
      W12 += m * h * h * p3 / (c1 * c2);
    }

    PlaneStressResponse r;
    const Eigen::Matrix2d A1 = n1 * n1.transpose(), A2 = n2 * n2.transpose();
    r.energy = W;
    r.stress = 2.0 * (W1 * A1 + W2 * A2);
    r.thickness_stretch = 1.0 / std::sqrt(c1 * c2);
    if (with_tangent) {
      const Eigen::Matrix2d P = n1 * n2.transpose() + n2 * n1.transpose();
      const double relative_gap = (c1 - c2) / c1;
      const double shear = relative_gap > 1e-8 ? (W1 - W2) / (c1 - c2) : W11 - W12;
      r.tangent = 4.0 * (W11 * detail::voigt_outer(A1, A1) + W22 * detail::voigt_outer(A2, A2) +
                         W12 * (detail::voigt_outer(A1, A2) + detail::voigt_outer(A2, A1)) +
                         0.5 * shear * detail::voigt_outer(P, P));
    }
    return r;
  }

 private:
  OgdenParameters p_;
};

}  // namespace valvefsi::solid
