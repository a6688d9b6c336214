#pragma once
// Three-dimensional, nearly incompressible forms of the leaflet materials for the brick
// element (docs/solid_fe-hexahedron.md). The shell's laws (material.hpp) only give the
// plane-stress form, so the volumetric-isochoric split lives here:
//   W(C) = W_iso(Cbar) + U(J),   Cbar = J^(-2/3) C,   U(J) = kappa/2 (J - 1)^2
//   S = J^(-2/3) Dev(Sbar) + J p C^-1,   Sbar = 2 dW_iso/dCbar,   Dev(A) = A - (A:C)/3 C^-1,
//   p = U'(J) = kappa (J - 1).
// MHGO (reference eq. 6) has its own (J - 1)^2 / D, i.e. kappa = 2/D. Ogden (eq. 7, Table 1)
// and neo-Hookean have no D in the reference; they are given a bulk modulus (by default the
// MHGO's 2/D = 200 MPa, so both tissue laws are equally near-incompressible).
// Every law works in the element's material frame (e1 circumferential, e2 radial, e3 normal).
#include <array>
#include <cmath>
#include <variant>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <fmt/format.h>

#include "valvefsi/solid/material.hpp"
#include "valvefsi/solid/material_error.hpp"

namespace valvefsi::solid {

// Energy per reference volume (J/m^3) and second Piola-Kirchhoff stress (Pa) of one point.
struct SolidResponse {
  double energy = 0.0;
  Eigen::Matrix3d stress = Eigen::Matrix3d::Zero();
};

namespace detail {

// Combines an isochoric response (energy Wbar and Sbar = 2 dWbar/dCbar at Cbar) with U(J).
inline SolidResponse split_response(const Eigen::Matrix3d& C, const Eigen::Matrix3d& C_inverse, double J,
                                    double iso_energy, const Eigen::Matrix3d& iso_stress_bar, double kappa) {
  const double j23 = std::cbrt(1.0 / (J * J));  // J^(-2/3)
  SolidResponse r;
  r.energy = iso_energy + 0.5 * kappa * (J - 1.0) * (J - 1.0);
  const double trace = (iso_stress_bar.cwiseProduct(C)).sum();
  r.stress = j23 * (iso_stress_bar - (trace / 3.0) * C_inverse) + J * kappa * (J - 1.0) * C_inverse;
  return r;
}

inline double checked_jacobian(const Eigen::Matrix3d& C, const char* law) {
  const double det = C.determinant();
  if (!(det > 0.0)) {
    throw MaterialStateError(fmt::format("{} (3D): det(C) = {:g} <= 0 (element inverted or degenerate)", law, det));
  }
  return std::sqrt(det);
}

}  // namespace detail

// W_iso = mu/2 (Ibar1 - 3).
class SolidNeoHookean {
 public:
  SolidNeoHookean(double shear_modulus_Pa, double bulk_modulus_Pa) : mu_(shear_modulus_Pa), kappa_(bulk_modulus_Pa) {}
  double shear_modulus() const { return mu_; }
  double bulk_modulus() const { return kappa_; }
  SolidResponse response(const Eigen::Matrix3d& C) const {
    const double J = detail::checked_jacobian(C, "neo-Hookean");
    const double j23 = std::cbrt(1.0 / (J * J));
    const double I1bar = j23 * C.trace();
    return detail::split_response(C, C.inverse(), J, 0.5 * mu_ * (I1bar - 3.0), mu_ * Eigen::Matrix3d::Identity(),
                                  kappa_);
  }

 private:
  double mu_, kappa_;
};

// Reference eq. 6 with the modified invariants Ibar1, Ibar4f; fibres a_f = cos(theta) e1 +- sin(theta) e2;
// a fibre with Ibar4f <= 1 carries nothing; kappa = 2/D.
class SolidMhgo {
 public:
  explicit SolidMhgo(const MhgoParameters& p = {}) : p_(p), kappa_(2.0 / p.d_per_Pa) {
    fibre_[0] = {std::cos(p.fibre_angle_rad), std::sin(p.fibre_angle_rad), 0.0};
    fibre_[1] = {std::cos(p.fibre_angle_rad), -std::sin(p.fibre_angle_rad), 0.0};
  }
  const MhgoParameters& parameters() const { return p_; }
  double shear_modulus() const { return 2.0 * p_.c10_Pa * p_.c01; }  // small-strain, fibres slack
  double bulk_modulus() const { return kappa_; }

  SolidResponse response(const Eigen::Matrix3d& C) const {
    const double J = detail::checked_jacobian(C, "MHGO");
    const double j23 = std::cbrt(1.0 / (J * J));
    const double I1bar = j23 * C.trace();
    const double matrix_arg = p_.c01 * (I1bar - 3.0);
    if (matrix_arg > kMaxExpArgument) {
      throw MaterialStateError(fmt::format(
          "MHGO (3D): matrix exponent C01 (Ibar1 - 3) = {:g} overflows exp at Ibar1 = {:g}, J = {:g} "
          "(C11 = {:g}, C22 = {:g}, C33 = {:g})", matrix_arg, I1bar, J, C(0, 0), C(1, 1), C(2, 2)));
    }
    const double e1 = std::exp(matrix_arg);
    double energy = p_.c10_Pa * (e1 - 1.0);
    Eigen::Matrix3d stress_bar = (2.0 * p_.c10_Pa * p_.c01 * e1) * Eigen::Matrix3d::Identity();
    for (int f = 0; f < 2; ++f) {
      const double I4bar = j23 * fibre_[f].dot(C * fibre_[f]);
      if (I4bar <= 1.0) continue;  // a compressed fibre carries nothing
      const double strain = I4bar - 1.0;
      const double arg = p_.k2 * strain * strain;
      if (arg > kMaxExpArgument) {
        throw MaterialStateError(fmt::format(
            "MHGO (3D): fibre {} exponent k2 (Ibar4 - 1)^2 = {:g} overflows exp at Ibar4 = {:g} "
            "(fibre stretch {:g}), Ibar1 = {:g}, J = {:g}", f + 1, arg, I4bar, std::sqrt(I4bar), I1bar, J));
      }
      const double e4 = std::exp(arg);
      energy += 0.5 * p_.k1_Pa / p_.k2 * (e4 - 1.0);
      stress_bar += (2.0 * p_.k1_Pa * strain * e4) * (fibre_[f] * fibre_[f].transpose());
    }
    return detail::split_response(C, C.inverse(), J, energy, stress_bar, kappa_);
  }

 private:
  MhgoParameters p_;
  double kappa_;
  std::array<Eigen::Vector3d, 2> fibre_;
};

// Reference eq. 7 in the isochoric stretches: W_iso = sum_p 2 mu_p / a_p^2 (sum_i lbar_i^a_p - 3),
// written in the eigenvalues cbar_i = lbar_i^2 of Cbar: Sbar = 2 sum_i dW/dcbar_i N_i N_i.
class SolidOgden {
 public:
  SolidOgden(const OgdenParameters& p, double bulk_modulus_Pa) : p_(p), kappa_(bulk_modulus_Pa) {}
  const OgdenParameters& parameters() const { return p_; }
  double shear_modulus() const { return p_.mu_Pa[0] + p_.mu_Pa[1]; }
  double bulk_modulus() const { return kappa_; }

  SolidResponse response(const Eigen::Matrix3d& C) const {
    const double J = detail::checked_jacobian(C, "Ogden");
    const double j23 = std::cbrt(1.0 / (J * J));
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(j23 * C);
    const Eigen::Vector3d c = eig.eigenvalues();
    if (!(c.minCoeff() > 0.0)) {
      throw MaterialStateError(fmt::format("Ogden (3D): Cbar has eigenvalue {:g} <= 0", c.minCoeff()));
    }
    double energy = 0.0;
    Eigen::Vector3d dW = Eigen::Vector3d::Zero();  // dW/dcbar_i
    for (int p = 0; p < 2; ++p) {
      const double a = p_.alpha[p], h = 0.5 * a;
      for (int i = 0; i < 3; ++i) {
        const double log_power = h * std::log(c(i));  // log of lbar_i^a
        if (log_power > kMaxExpArgument) {
          throw MaterialStateError(fmt::format(
              "Ogden (3D): stretch power overflows (term {}: a = {:g}) at lbar = ({:g}, {:g}, {:g}), J = {:g}", p + 1,
              a, std::sqrt(c(0)), std::sqrt(c(1)), std::sqrt(c(2)), J));
        }
        const double power = std::exp(log_power);
        energy += 2.0 * p_.mu_Pa[p] / (a * a) * power;
        dW(i) += p_.mu_Pa[p] / a * power / c(i);
      }
      energy -= 2.0 * p_.mu_Pa[p] / (a * a) * 3.0;
    }
    const Eigen::Matrix3d& N = eig.eigenvectors();
    const Eigen::Matrix3d stress_bar = 2.0 * N * dW.asDiagonal() * N.transpose();
    return detail::split_response(C, C.inverse(), J, energy, stress_bar, kappa_);
  }

 private:
  OgdenParameters p_;
  double kappa_;
};

// W = lambda/2 (tr E)^2 + mu E:E (compressible; verification at small strain, large rotation).
class SolidSaintVenantKirchhoff {
 public:
  SolidSaintVenantKirchhoff(double youngs_modulus_Pa, double poisson_ratio)
      : E_(youngs_modulus_Pa), nu_(poisson_ratio), mu_(youngs_modulus_Pa / (2.0 * (1.0 + poisson_ratio))),
        lambda_(youngs_modulus_Pa * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio))) {}
  double shear_modulus() const { return mu_; }
  double bulk_modulus() const { return lambda_ + 2.0 * mu_ / 3.0; }
  double youngs_modulus() const { return E_; }
  double poisson_ratio() const { return nu_; }
  SolidResponse response(const Eigen::Matrix3d& C) const {
    const Eigen::Matrix3d E = 0.5 * (C - Eigen::Matrix3d::Identity());
    SolidResponse r;
    r.energy = 0.5 * lambda_ * E.trace() * E.trace() + mu_ * E.cwiseProduct(E).sum();
    r.stress = lambda_ * E.trace() * Eigen::Matrix3d::Identity() + 2.0 * mu_ * E;
    return r;
  }

 private:
  double E_, nu_, mu_, lambda_;
};

using SolidMaterial = std::variant<SolidOgden, SolidMhgo, SolidNeoHookean, SolidSaintVenantKirchhoff>;

// Default bulk modulus of the laws without a D: the MHGO's 2/D with the reference's D = 1e-5 /kPa.
inline constexpr double kDefaultTissueBulkModulus_Pa = 2.0 / (1.0e-5 / 1.0e3);

// The 3D form of a shell material: MHGO keeps its D; Ogden and neo-Hookean take `bulk_modulus_Pa`;
// Saint Venant-Kirchhoff keeps its E and nu.
inline SolidMaterial solid_material_from(const Material& m, double bulk_modulus_Pa = kDefaultTissueBulkModulus_Pa) {
  struct Convert {
    double kappa;
    SolidMaterial operator()(const Ogden& law) const { return SolidOgden(law.parameters(), kappa); }
    SolidMaterial operator()(const Mhgo& law) const { return SolidMhgo(law.parameters()); }
    SolidMaterial operator()(const NeoHookean& law) const { return SolidNeoHookean(law.shear_modulus(), kappa); }
    SolidMaterial operator()(const SaintVenantKirchhoff& law) const {
      return SolidSaintVenantKirchhoff(law.youngs_modulus(), law.poisson_ratio());
    }
  };
  return std::visit(Convert{bulk_modulus_Pa}, m);
}

// The thin-sheet (plane-stress, incompressible) form of a 3D law, for the free surfaces of a brick.
inline Material plane_stress_form(const SolidMaterial& m) {
  struct Convert {
    Material operator()(const SolidOgden& law) const { return Ogden(law.parameters()); }
    Material operator()(const SolidMhgo& law) const { return Mhgo(law.parameters()); }
    Material operator()(const SolidNeoHookean& law) const { return NeoHookean(law.shear_modulus()); }
    Material operator()(const SolidSaintVenantKirchhoff& law) const {
      return SaintVenantKirchhoff(law.youngs_modulus(), law.poisson_ratio());
    }
  };
  return std::visit(Convert{}, m);
}

inline double bulk_modulus(const SolidMaterial& m) {
  return std::visit([](const auto& law) { return law.bulk_modulus(); }, m);
}
inline double shear_modulus(const SolidMaterial& m) {
  return std::visit([](const auto& law) { return law.shear_modulus(); }, m);
}

}  // namespace valvefsi::solid
