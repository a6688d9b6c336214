#pragma once
// Modified Holzapfel-Gasser-Ogden tissue (reference eq. 6):
//   W = C10 {exp[C01 (I1 - 3)] - 1} + k1/(2 k2) sum_{f=1,2} {exp[k2 (I4f - 1)^2] - 1} + (J - 1)^2 / D
// Two fibre families at +-theta from the circumferential axis (e1 of the material frame);
// a fibre carries no load while compressed (I4f <= 1). D only enters the solid (brick) form.
#include <array>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "valvefsi/solid/invariant_plane_stress.hpp"
#include "valvefsi/solid/material_error.hpp"

namespace valvefsi::solid {

struct MhgoParameters {
  double c10_Pa = 30.03e3;                       // matrix stiffness C10
  double c01 = 3.47;                             // matrix exponent C01 (dimensionless)
  double k1_Pa = 74.5e3;                         // fibre stiffness k1
  double k2 = 63.19;                             // fibre exponent k2 (dimensionless)
  double fibre_angle_rad = 43.11 * M_PI / 180.0; // theta, from the circumferential axis
  double d_per_Pa = 1.0e-5 / 1.0e3;              // compressibility D (1e-5 /kPa)
};

class Mhgo {
 public:
  explicit Mhgo(const MhgoParameters& p = {}) : p_(p) {
    fibre_[0] = {std::cos(p.fibre_angle_rad), std::sin(p.fibre_angle_rad)};
    fibre_[1] = {std::cos(p.fibre_angle_rad), -std::sin(p.fibre_angle_rad)};
  }

  const MhgoParameters& parameters() const { return p_; }
  const Eigen::Vector2d& fibre_direction(int f) const { return fibre_[f]; }
  // Small-strain in-plane modulus (matrix only; fibres are slack at rest), for time steps.
  double initial_membrane_modulus() const { return 8.0 * p_.c10_Pa * p_.c01; }

  PlaneStressResponse plane_stress(const Eigen::Matrix2d& C, bool with_tangent = true) const {
    const double detC = C.determinant();
    if (!(detC > 0.0)) {
      throw MaterialStateError(fmt::format(
          "MHGO: in-plane det(C) = {:g} <= 0 (element inverted or degenerate)", detC));
    }
    const double I1 = C.trace() + 1.0 / detC;
    const double matrix_arg = p_.c01 * (I1 - 3.0);
    if (matrix_arg > kMaxExpArgument) {
      throw MaterialStateError(fmt::format(
          "MHGO: matrix exponent C01 (I1 - 3) = {:g} overflows exp at I1 = {:g} "
          "(C11 = {:g}, C22 = {:g}, C12 = {:g}, lambda3 = {:g})",
          matrix_arg, I1, C(0, 0), C(1, 1), C(0, 1), std::sqrt(1.0 / detC)));
    }
    const double e1 = std::exp(matrix_arg);
    const detail::IsotropicDerivatives iso{p_.c10_Pa * (e1 - 1.0), p_.c10_Pa * p_.c01 * e1,
                                           p_.c10_Pa * p_.c01 * p_.c01 * e1};
    std::array<detail::FibreDerivatives, 2> fibres;
    for (int f = 0; f < 2; ++f) {
      fibres[f].direction = fibre_[f];
      const double I4 = fibre_[f].dot(C * fibre_[f]);
      if (I4 <= 1.0) continue;  // a compressed fibre carries nothing
      const double strain = I4 - 1.0;
      const double arg = p_.k2 * strain * strain;
      if (arg > kMaxExpArgument) {
        throw MaterialStateError(fmt::format(
            "MHGO: fibre {} exponent k2 (I4 - 1)^2 = {:g} overflows exp at I4 = {:g} "
            "(fibre stretch {:g}), I1 = {:g} (C11 = {:g}, C22 = {:g}, C12 = {:g})",
            f + 1, arg, I4, std::sqrt(I4), I1, C(0, 0), C(1, 1), C(0, 1)));
      }
      const double e4 = std::exp(arg);
      fibres[f].energy = 0.5 * p_.k1_Pa / p_.k2 * (e4 - 1.0);
      fibres[f].d4 = p_.k1_Pa * strain * e4;
      fibres[f].d44 = p_.k1_Pa * (1.0 + 2.0 * p_.k2 * strain * strain) * e4;
    }
    return detail::assemble_plane_stress<2>(C, iso, fibres, with_tangent);
  }

 private:
  MhgoParameters p_;
  std::array<Eigen::Vector2d, 2> fibre_;
};

}  // namespace valvefsi::solid
