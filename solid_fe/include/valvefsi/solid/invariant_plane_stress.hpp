#pragma once
// Plane-stress incompressible response of an energy written in the invariants I1 = tr C and
// I4 = a.C.a: with lambda3^2 = C33 = 1/det(C2) the through-thickness pressure is eliminated
// (sigma33 = 0) and W(C2) = Psi(I1(C2), I4(C2)) with I1 = tr C2 + 1/det C2.
//   S = 2 dW/dC2 = 2 [Psi_1 (I - C33 C2^-1) + sum_f Psi_4f a_f a_f]
//   dS/dE = 4 d2W/dC2 dC2 = 4 [Psi_11 G(x)G + Psi_1 C33 (Ci(x)Ci + Ci(.)Ci) + sum_f Psi_44f A_f(x)A_f]
// with G = I - C33 C2^-1, Ci = C2^-1, A_f = a_f a_f and (.) the symmetrised product.
#include <array>

#include <Eigen/Core>
#include <Eigen/LU>

#include "valvefsi/solid/material_response.hpp"

namespace valvefsi::solid::detail {

// Index pairs of the Voigt components [11, 22, 12].
inline constexpr std::array<std::array<int, 2>, 3> kVoigtPairs{{{0, 0}, {1, 1}, {0, 1}}};

inline Eigen::Matrix3d voigt_outer(const Eigen::Matrix2d& X, const Eigen::Matrix2d& Y) {
  const Eigen::Vector3d x = to_voigt(X);
  const Eigen::Vector3d y = to_voigt(Y);
  return x * y.transpose();
}

// Voigt form of the symmetrised product (A (.) A)_ijkl = (A_ik A_jl + A_il A_jk) / 2.
inline Eigen::Matrix3d voigt_symmetric_product(const Eigen::Matrix2d& A) {
  Eigen::Matrix3d D;
  for (int I = 0; I < 3; ++I) {
    for (int J = 0; J < 3; ++J) {
      const int i = kVoigtPairs[I][0], j = kVoigtPairs[I][1];
      const int k = kVoigtPairs[J][0], l = kVoigtPairs[J][1];
      D(I, J) = 0.5 * (A(i, k) * A(j, l) + A(i, l) * A(j, k));
    }
  }
  return D;
}

// Derivatives of the isotropic part Psi(I1) and of one fibre term Psi_f(I4f).
struct IsotropicDerivatives {
  double energy = 0, d1 = 0, d11 = 0;
};
struct FibreDerivatives {
  Eigen::Vector2d direction = Eigen::Vector2d::UnitX();  // unit fibre direction in the plane
  double energy = 0, d4 = 0, d44 = 0;
};

inline double incompressible_c33(const Eigen::Matrix2d& C) { return 1.0 / C.determinant(); }

template <int NumFibres>
PlaneStressResponse assemble_plane_stress(const Eigen::Matrix2d& C, const IsotropicDerivatives& iso,
                                          const std::array<FibreDerivatives, NumFibres>& fibres,
                                          bool with_tangent) {
  PlaneStressResponse r;
  const Eigen::Matrix2d Ci = C.inverse();
  const double c33 = 1.0 / C.determinant();
  const Eigen::Matrix2d G = Eigen::Matrix2d::Identity() - c33 * Ci;
  r.energy = iso.energy;
  r.stress = 2.0 * iso.d1 * G;
  for (const auto& f : fibres) {
    const Eigen::Matrix2d A = f.direction * f.direction.transpose();
    r.energy += f.energy;
    r.stress += 2.0 * f.d4 * A;
  }
  r.thickness_stretch = std::sqrt(c33);
  if (with_tangent) {
    r.tangent = 4.0 * (iso.d11 * voigt_outer(G, G) +
                       iso.d1 * c33 * (voigt_outer(Ci, Ci) + voigt_symmetric_product(Ci)));
    for (const auto& f : fibres) {
      const Eigen::Matrix2d A = f.direction * f.direction.transpose();
      r.tangent += 4.0 * f.d44 * voigt_outer(A, A);
    }
  }
  return r;
}

}  // namespace valvefsi::solid::detail
