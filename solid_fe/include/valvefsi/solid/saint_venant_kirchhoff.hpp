#pragma once
// Saint Venant-Kirchhoff solid, W = lambda/2 (tr E)^2 + mu E:E, in plane stress (S33 = 0
// condenses lambda to 2 lambda mu / (lambda + 2 mu)). Compressible; for verification
// (patch tests, the elastica) where small strains and large rotations are wanted.
#include <cmath>
#include <string>

#include "valvefsi/solid/material_error.hpp"
#include "valvefsi/solid/material_response.hpp"

namespace valvefsi::solid {

class SaintVenantKirchhoff {
 public:
  SaintVenantKirchhoff(double youngs_modulus_Pa, double poisson_ratio)
      : E_(youngs_modulus_Pa), nu_(poisson_ratio) {
    const double factor = E_ / (1.0 - nu_ * nu_);
    D_ << factor, factor * nu_, 0.0,  //
        factor * nu_, factor, 0.0,    //
        0.0, 0.0, factor * 0.5 * (1.0 - nu_);
  }

  double youngs_modulus() const { return E_; }
  double poisson_ratio() const { return nu_; }
  double initial_membrane_modulus() const { return E_ / (1.0 - nu_ * nu_); }

  PlaneStressResponse plane_stress(const Eigen::Matrix2d& C, bool /*with_tangent*/ = true) const {
    const Eigen::Matrix2d E = 0.5 * (C - Eigen::Matrix2d::Identity());
    const Eigen::Vector3d e{E(0, 0), E(1, 1), 2.0 * E(0, 1)};
    const Eigen::Vector3d s = D_ * e;
    PlaneStressResponse r;
    r.energy = 0.5 * e.dot(s);
    r.stress << s(0), s(2), s(2), s(1);
    r.tangent = D_;
    // E33 from S33 = 0 in 3D: E33 = -nu/(1-nu) (E11 + E22).
    const double c33 = 1.0 - 2.0 * nu_ / (1.0 - nu_) * E.trace();
    r.thickness_stretch = c33 > 0.0 ? std::sqrt(c33) : 0.0;
    return r;
  }

 private:
  double E_, nu_;
  Eigen::Matrix3d D_;
};

}  // namespace valvefsi::solid
