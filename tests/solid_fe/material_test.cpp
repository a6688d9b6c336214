// Materials: stress = derivative of the energy, tangent = derivative of the stress (central
// differences at random deformations), and closed-form incompressible uniaxial and equibiaxial
// Cauchy stress (the reference's Fig. 2a curves).
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "valvefsi/solid/material.hpp"

namespace valvefsi::solid {
namespace {

// C from the Voigt strain [E11, E22, 2 E12].
Eigen::Matrix2d c_from_strain(const Eigen::Vector3d& e) {
  Eigen::Matrix2d C;
  C << 1.0 + 2.0 * e(0), e(2), e(2), 1.0 + 2.0 * e(1);
  return C;
}

std::vector<Material> all_materials() {
  return {Ogden{}, Mhgo{}, NeoHookean{100e3}, SaintVenantKirchhoff{1e6, 0.3}};
}

// Random moderate deformations: stretches 0.85..1.15 at a random angle, like a loaded leaflet.
std::vector<Eigen::Vector3d> random_strains(int count) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> stretch(0.85, 1.15), angle(0.0, M_PI);
  std::vector<Eigen::Vector3d> strains;
  for (int i = 0; i < count; ++i) {
    const double l1 = stretch(rng), l2 = stretch(rng), phi = angle(rng);
    const Eigen::Matrix2d R = Eigen::Rotation2Dd(phi).toRotationMatrix();
    const Eigen::Matrix2d C = R * Eigen::Vector2d(l1 * l1, l2 * l2).asDiagonal() * R.transpose();
    strains.emplace_back(0.5 * (C(0, 0) - 1.0), 0.5 * (C(1, 1) - 1.0), C(0, 1));
  }
  return strains;
}

TEST(MaterialDerivatives, StressIsTheDerivativeOfTheEnergy) {
  for (const Material& m : all_materials()) {
    for (const Eigen::Vector3d& e : random_strains(40)) {
      const PlaneStressResponse r = plane_stress(m, c_from_strain(e));
      const Eigen::Vector3d s = to_voigt(r.stress);
      for (int j = 0; j < 3; ++j) {
        const double h = 1e-7;
        Eigen::Vector3d ep = e, em = e;
        ep(j) += h;
        em(j) -= h;
        const double fd = (plane_stress(m, c_from_strain(ep)).energy - plane_stress(m, c_from_strain(em)).energy) / (2 * h);
        EXPECT_NEAR(fd, s(j), 1e-6 * s.cwiseAbs().maxCoeff() + 1e-3)
            << material_name(m) << " component " << j << " at E = " << e.transpose();
      }
    }
  }
}

TEST(MaterialDerivatives, TangentIsTheDerivativeOfTheStress) {
  for (const Material& m : all_materials()) {
    for (const Eigen::Vector3d& e : random_strains(40)) {
      const PlaneStressResponse r = plane_stress(m, c_from_strain(e));
      for (int j = 0; j < 3; ++j) {
        const double h = 1e-7;
        Eigen::Vector3d ep = e, em = e;
        ep(j) += h;
        em(j) -= h;
        const Eigen::Vector3d fd = (to_voigt(plane_stress(m, c_from_strain(ep)).stress) -
                                    to_voigt(plane_stress(m, c_from_strain(em)).stress)) / (2 * h);
        const double scale = r.tangent.cwiseAbs().maxCoeff();
        for (int i = 0; i < 3; ++i) {
          EXPECT_NEAR(fd(i), r.tangent(i, j), 2e-6 * scale)
              << material_name(m) << " D(" << i << "," << j << ") at E = " << e.transpose();
        }
      }
    }
  }
}

TEST(MaterialDerivatives, OgdenTangentIsContinuousAtEqualStretches) {
  // The principal-stretch formula switches to its limit at c1 = c2; both sides must agree.
  const Ogden ogden;
  const Eigen::Matrix2d equal = 1.1 * Eigen::Matrix2d::Identity();
  Eigen::Matrix2d nearly = equal;
  nearly(0, 0) += 1e-6;
  const Eigen::Matrix3d a = ogden.plane_stress(equal).tangent, b = ogden.plane_stress(nearly).tangent;
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-3 * a.cwiseAbs().maxCoeff());
}

TEST(MaterialDerivatives, AllMaterialsAreStressFreeAtRestWithTheRightModulus) {
  for (const Material& m : all_materials()) {
    const PlaneStressResponse r = plane_stress(m, Eigen::Matrix2d::Identity());
    EXPECT_LT(r.stress.cwiseAbs().maxCoeff(), 1e-9) << material_name(m);
    EXPECT_NEAR(r.energy, 0.0, 1e-12) << material_name(m);
    if (!std::holds_alternative<Mhgo>(m)) {
      // Isotropic laws: D11 equals the quoted small-strain membrane modulus.
      EXPECT_NEAR(r.tangent(0, 0), initial_membrane_modulus(m), 1e-9 * r.tangent(0, 0)) << material_name(m);
    }
  }
}

// Independent closed forms of the incompressible reference's curves.
double ogden_equibiaxial_cauchy(const OgdenParameters& p, double l) {
  double s = 0;
  for (int i = 0; i < 2; ++i) s += 2.0 * p.mu_Pa[i] / p.alpha[i] * (std::pow(l, p.alpha[i]) - std::pow(l, -2.0 * p.alpha[i]));
  return s;
}
double ogden_uniaxial_cauchy(const OgdenParameters& p, double l) {
  double s = 0;
  for (int i = 0; i < 2; ++i) s += 2.0 * p.mu_Pa[i] / p.alpha[i] * (std::pow(l, p.alpha[i]) - std::pow(l, -0.5 * p.alpha[i]));
  return s;
}
// MHGO equibiaxial stretch l: I1 = 2 l^2 + l^-4, both fibres have I4 = l^2.
Eigen::Vector2d mhgo_equibiaxial_cauchy(const MhgoParameters& p, double l) {
  const double I1 = 2 * l * l + std::pow(l, -4);
  const double matrix = 2 * p.c10_Pa * p.c01 * std::exp(p.c01 * (I1 - 3)) * (l * l - std::pow(l, -4));
  const double fibre = 2 * 2 * p.k1_Pa * (l * l - 1) * std::exp(p.k2 * std::pow(l * l - 1, 2)) * l * l;
  const double c = std::cos(p.fibre_angle_rad), s = std::sin(p.fibre_angle_rad);
  return {matrix + fibre * c * c, matrix + fibre * s * s};
}

// Cauchy stress of the sheet from the material: sigma = F S F^T for diagonal C (J = 1).
Eigen::Vector2d cauchy_diagonal(const Material& m, double l1, double l2) {
  const Eigen::Matrix2d C = Eigen::Vector2d(l1 * l1, l2 * l2).asDiagonal();
  const Eigen::Matrix2d S = plane_stress(m, C).stress;
  return {l1 * l1 * S(0, 0), l2 * l2 * S(1, 1)};
}

// Lateral stretch that leaves the uniaxial sheet free (S22 = 0), by bisection.
double free_lateral_stretch(const Material& m, double l1) {
  double lo = 0.5, hi = 1.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (cauchy_diagonal(m, l1, mid)(1) > 0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

TEST(MaterialClosedForm, OgdenEquibiaxialAndUniaxial) {
  const Ogden ogden;
  for (double l = 1.01; l <= 1.2; l += 0.01) {
    const Eigen::Vector2d eq = cauchy_diagonal(ogden, l, l);
    const double ref = ogden_equibiaxial_cauchy(ogden.parameters(), l);
    EXPECT_NEAR(eq(0), ref, 1e-10 * ref) << "equibiaxial l = " << l;
    EXPECT_NEAR(eq(1), ref, 1e-10 * ref);
    const double lateral = free_lateral_stretch(ogden, l);
    EXPECT_NEAR(lateral, 1.0 / std::sqrt(l), 1e-9) << "isotropic: lateral = thickness stretch";
    const double uni = cauchy_diagonal(ogden, l, lateral)(0);
    EXPECT_NEAR(uni, ogden_uniaxial_cauchy(ogden.parameters(), l), 1e-6 * uni) << "uniaxial l = " << l;
  }
}

TEST(MaterialClosedForm, MhgoEquibiaxialIsAnisotropicAndStiffensSteeply) {
  const Mhgo mhgo;
  for (double l = 1.01; l <= 1.15; l += 0.01) {
    const Eigen::Vector2d got = cauchy_diagonal(mhgo, l, l);
    const Eigen::Vector2d ref = mhgo_equibiaxial_cauchy(mhgo.parameters(), l);
    EXPECT_NEAR(got(0), ref(0), 1e-10 * ref(0)) << "circumferential at l = " << l;
    EXPECT_NEAR(got(1), ref(1), 1e-10 * ref(1)) << "radial at l = " << l;
    EXPECT_GT(got(0), got(1)) << "theta < 45 deg puts more fibre along the circumference";
  }
  const double at10 = cauchy_diagonal(mhgo, 1.10, 1.10)(0), at15 = cauchy_diagonal(mhgo, 1.15, 1.15)(0);
  EXPECT_GT(at15 / at10, 10.0) << "sigma(10 %) = " << at10 << " Pa, sigma(15 %) = " << at15 << " Pa";
}

TEST(MaterialClosedForm, NeoHookeanUniaxial) {
  const double mu = 50e3;
  const NeoHookean nh{mu};
  for (double l = 1.05; l <= 2.0; l += 0.05) {
    const double lateral = free_lateral_stretch(nh, l);
    EXPECT_NEAR(lateral, 1 / std::sqrt(l), 1e-9);
    EXPECT_NEAR(cauchy_diagonal(nh, l, lateral)(0), mu * (l * l - 1 / l), 1e-6 * mu * l * l);
  }
}

TEST(MaterialClosedForm, FibresCarryNoCompression) {
  // Compress along the circumferential direction only: fibre strains are negative, so the
  // MHGO response equals its matrix part alone.
  const Mhgo mhgo;
  MhgoParameters matrix_only = mhgo.parameters();
  matrix_only.k1_Pa = 0.0;
  const Eigen::Matrix2d C = Eigen::Vector2d(0.9 * 0.9, 1.0).asDiagonal();
  EXPECT_LT((mhgo.plane_stress(C).stress - Mhgo(matrix_only).plane_stress(C).stress).norm(), 1e-9);
}

TEST(MaterialOverflow, ErrorNamesTheState) {
  const Mhgo mhgo;
  const Eigen::Matrix2d C = Eigen::Vector2d(3.0 * 3.0, 1.0).asDiagonal();
  try {
    mhgo.plane_stress(C);
    FAIL() << "expected an overflow error";
  } catch (const MaterialStateError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("I4"), std::string::npos) << what;
    EXPECT_NE(what.find("overflows"), std::string::npos) << what;
  }
  const Ogden ogden;
  EXPECT_THROW(ogden.plane_stress(Eigen::Vector2d(1e-12, 1e-12).asDiagonal()), MaterialStateError);
  EXPECT_THROW(NeoHookean{1.0}.plane_stress(Eigen::Vector2d(-1.0, 1.0).asDiagonal()), MaterialStateError);
}

}  // namespace
}  // namespace valvefsi::solid
