#pragma once
// What a material returns for one material point, in the element's material frame
// (e1 = circumferential, e2 = radial, e3 = normal).
#include <Eigen/Core>

namespace valvefsi::solid {

// Plane-stress response of a thin sheet: input is the in-plane right Cauchy-Green tensor C
// (2x2); the through-thickness stretch is eliminated by sigma33 = 0.
// Voigt order [11, 22, 12]; strains use the engineering shear 2*E12, so that
// stress_i = d energy / d strain_i and tangent_ij = d stress_i / d strain_j.
struct PlaneStressResponse {
  double energy = 0.0;                              // strain energy per reference volume (J/m^3)
  Eigen::Matrix2d stress = Eigen::Matrix2d::Zero();  // second Piola-Kirchhoff stress S (Pa)
  Eigen::Matrix3d tangent = Eigen::Matrix3d::Zero(); // dS/dE in Voigt form (Pa)
  double thickness_stretch = 1.0;                    // lambda3 = current / reference thickness
};

inline Eigen::Vector3d to_voigt(const Eigen::Matrix2d& S) { return {S(0, 0), S(1, 1), S(0, 1)}; }

}  // namespace valvefsi::solid
