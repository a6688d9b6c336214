#pragma once
// Incompressible neo-Hookean solid, W = mu/2 (I1 - 3); for verification against closed forms.
#include <array>
#include <string>

#include "valvefsi/solid/invariant_plane_stress.hpp"
#include "valvefsi/solid/material_error.hpp"

namespace valvefsi::solid {

class NeoHookean {
 public:
  explicit NeoHookean(double shear_modulus_Pa) : mu_(shear_modulus_Pa) {}

  double shear_modulus() const { return mu_; }
  // Small-strain in-plane modulus of the incompressible sheet (4 mu), for time-step estimates.
  double initial_membrane_modulus() const { return 4.0 * mu_; }

  PlaneStressResponse plane_stress(const Eigen::Matrix2d& C, bool with_tangent = true) const {
    const double detC = C.determinant();
    if (!(detC > 0.0)) {
      throw MaterialStateError("neo-Hookean: in-plane det(C) = " + std::to_string(detC) +
                               " <= 0 (element inverted or degenerate)");
    }
    const double I1 = C.trace() + 1.0 / detC;
    const detail::IsotropicDerivatives iso{0.5 * mu_ * (I1 - 3.0), 0.5 * mu_, 0.0};
    return detail::assemble_plane_stress<0>(C, iso, {}, with_tangent);
  }

 private:
  double mu_;
};

}  // namespace valvefsi::solid
