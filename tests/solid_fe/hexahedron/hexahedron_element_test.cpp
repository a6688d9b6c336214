// The brick element and the 3D materials: stress = energy derivative, closed-form uniaxial and
// equibiaxial stress, patch tests, exact energy gradient, calibrated hourglass bending, loads.
#include <cmath>
#include <functional>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "hex_test_meshes.hpp"
#include "valvefsi/solid/hexahedron_solver.hpp"

namespace valvefsi::solid {
namespace {

using testing::box_mesh;

HexahedronModel model_of(const Mesh& mesh, double density = 1100.0) {
  return build_hexahedron_model(mesh, {density, {}}, "test mesh");
}

// Internal forces and energies of all elements at x with the material's small-strain moduli
// (or the given ones).
struct Assembled {
  Eigen::Matrix3Xd force;
  double strain_energy = 0, hourglass_energy = 0;
};
Assembled assemble(const HexahedronModel& model, const SolidMaterial& material, const Eigen::Matrix3Xd& x,
                   const HexModuli* fixed_moduli = nullptr) {
  Assembled out;
  out.force = Eigen::Matrix3Xd::Zero(3, x.cols());
  const double mu = shear_modulus(material), kappa = bulk_modulus(material);
  std::visit(
      [&](const auto& law) {
        for (const auto& el : model.elements) {
          HexModuli m = fixed_moduli ? *fixed_moduli : hex_moduli(mu, kappa);
          const auto r = hex_element_force(el, law, x, model.density, m, false, out.force);
          out.strain_energy += r.strain_energy;
          out.hourglass_energy += r.hourglass_energy;
        }
      },
      material);
  return out;
}

Eigen::Matrix3d random_stretch(std::mt19937& rng, double amplitude) {
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  Eigen::Matrix3d F;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) F(i, j) = (i == j ? 1.0 : 0.0) + u(rng);
  return F;
}

std::vector<SolidMaterial> all_laws(double bulk_modulus) {
  MhgoParameters mhgo;
  mhgo.d_per_Pa = 2.0 / bulk_modulus;
  return {SolidOgden(OgdenParameters{}, bulk_modulus), SolidMhgo(mhgo), SolidNeoHookean(1e5, bulk_modulus),
          SolidSaintVenantKirchhoff(1e6, 0.3)};
}

TEST(HexahedronMaterial, StressIsTheDerivativeOfTheEnergy) {
  std::mt19937 rng(11);
  for (const auto& material : all_laws(5e6)) {
    for (int trial = 0; trial < 20; ++trial) {
      const Eigen::Matrix3d F = random_stretch(rng, 0.08);
      const Eigen::Matrix3d C = F.transpose() * F;
      Eigen::Matrix3d D = random_stretch(rng, 1.0) - Eigen::Matrix3d::Identity();
      D = 0.5 * (D + D.transpose()).eval();  // direction in E
      std::visit(
          [&](const auto& law) {
            const auto r = law.response(C);
            const double h = 1e-6;
            const double dW = (law.response(C + 2.0 * h * D).energy - law.response(C - 2.0 * h * D).energy) / (2 * h);
            const double expected = r.stress.cwiseProduct(D).sum();
            EXPECT_NEAR(dW, expected, 1e-6 * r.stress.norm() * D.norm() + 1e-9)
                << "trial " << trial << " law " << material.index();
          },
          material);
    }
  }
}

TEST(HexahedronMaterial, ZeroStressAtRestAndPureVolumeChangeGivesPressure) {
  for (const auto& material : all_laws(5e6)) {
    std::visit(
        [&](const auto& law) {
          const auto rest = law.response(Eigen::Matrix3d::Identity());
          EXPECT_LT(rest.stress.norm(), 1e-6);
          EXPECT_NEAR(rest.energy, 0.0, 1e-9);
        },
        material);
  }
  // Isotropic laws under a pure dilatation J: S = J p C^-1 with p = kappa (J - 1).
  const double J = 1.01, kappa = 5e6;
  const Eigen::Matrix3d C = std::cbrt(J * J) * Eigen::Matrix3d::Identity();
  const auto r = SolidNeoHookean(1e5, kappa).response(C);
  EXPECT_NEAR(r.stress(0, 0), J * kappa * (J - 1.0) / std::cbrt(J * J), 1e-6 * kappa * (J - 1.0));
  EXPECT_NEAR(r.stress(0, 1), 0.0, 1e-9);
}

// Positions of a mesh deformed homogeneously by F.
Eigen::Matrix3Xd deformed(const Mesh& mesh, const Eigen::Matrix3d& F, const Eigen::Vector3d& c = Eigen::Vector3d::Zero()) {
  return (F * mesh.nodes).colwise() + c;
}

double face_force(const Assembled& a, const Mesh& mesh, const std::string& face, int component) {
  double sum = 0;
  for (const auto n : mesh.node_sets.at(face)) sum += a.force(component, n);
  return sum;
}

// Lateral stretch making the lateral first Piola-Kirchhoff traction zero (bisection).
double free_stretch(const std::function<double(double)>& lateral_traction, double lo, double hi) {
  double f_lo = lateral_traction(lo);
  for (int it = 0; it < 100; ++it) {
    const double mid = 0.5 * (lo + hi);
    const double f_mid = lateral_traction(mid);
    if ((f_mid > 0) == (f_lo > 0)) {
      lo = mid;
      f_lo = f_mid;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

class UniaxialStress : public ::testing::TestWithParam<double> {};  // parameter: jitter (0 = one element)

TEST_P(UniaxialStress, MatchesIncompressibleClosedForms) {
  const double jitter = GetParam();
  const Mesh mesh = jitter > 0 ? box_mesh(1.0, 1.0, 1.0, 2, 2, 2, jitter) : box_mesh(1.0, 1.0, 1.0, 1, 1, 1);
  const HexahedronModel model = model_of(mesh);
  const double kappa = 1e13;  // nearly incompressible: J - 1 < 1e-6 (Ogden's a = 67.7 amplifies it)
  const OgdenParameters ogden;
  const double mu = 1e5;
  for (int law = 0; law < 2; ++law) {
    const SolidMaterial material = law == 0 ? SolidMaterial(SolidNeoHookean(mu, kappa)) : SolidMaterial(SolidOgden(ogden, kappa));
    for (const double stretch : {1.02, 1.08, 1.15}) {
      const auto at = [&](double lateral) {
        return assemble(model, material, deformed(mesh, Eigen::Vector3d(stretch, lateral, lateral).asDiagonal()));
      };
      const double lt = free_stretch([&](double l) { return face_force(at(l), mesh, "y1", 1); },
                                     0.95 / std::sqrt(stretch), 1.05 / std::sqrt(stretch));
      const Assembled a = at(lt);
      const double P11 = face_force(a, mesh, "x1", 0);  // reference area 1
      const double sigma = P11 * stretch / (stretch * lt * lt);
      double expected = 0;
      if (law == 0) {
        expected = mu * (stretch * stretch - 1.0 / stretch);
      } else {
        for (int p = 0; p < 2; ++p) {
          const double al = ogden.alpha[p];
          expected += 2.0 * ogden.mu_Pa[p] / al * (std::pow(stretch, al) - std::pow(stretch, -0.5 * al));
        }
      }
      EXPECT_NEAR(sigma, expected, 1e-4 * std::abs(expected)) << "law " << law << " stretch " << stretch;
      EXPECT_NEAR(lt, 1.0 / std::sqrt(stretch), 1e-4);
      EXPECT_LT(a.hourglass_energy, 1e-12 * a.strain_energy);
    }
  }
}

TEST_P(UniaxialStress, MhgoEquibiaxialMatchesThePlaneStressSheet) {
  const double jitter = GetParam();
  const Mesh mesh = jitter > 0 ? box_mesh(1.0, 1.0, 1.0, 2, 2, 2, jitter) : box_mesh(1.0, 1.0, 1.0, 1, 1, 1);
  const HexahedronModel model = model_of(mesh);
  MhgoParameters p;
  p.d_per_Pa = 1e-13;  // kappa = 2e13 Pa: J - 1 < 1e-5 (the fibre exponential amplifies it)
  const SolidMaterial material = SolidMhgo(p);
  const Mhgo sheet(p);
  for (const double stretch : {1.05, 1.10, 1.15}) {
    const auto at = [&](double thickness) {
      return assemble(model, material, deformed(mesh, Eigen::Vector3d(stretch, stretch, thickness).asDiagonal()));
    };
    const double l3 = free_stretch([&](double l) { return face_force(at(l), mesh, "z1", 2); },
                                   0.95 / (stretch * stretch), 1.05 / (stretch * stretch));
    const Assembled a = at(l3);
    const double J = stretch * stretch * l3;
    // sigma_ii = P_ii lambda_i / J, P_ii = face force over the reference area 1.
    const double s11 = face_force(a, mesh, "x1", 0) * stretch / J;
    const double s22 = face_force(a, mesh, "y1", 1) * stretch / J;
    const auto closed = sheet.plane_stress(Eigen::Vector2d(stretch * stretch, stretch * stretch).asDiagonal());
    EXPECT_NEAR(s11, stretch * stretch * closed.stress(0, 0), 2e-4 * std::abs(s11)) << stretch;
    EXPECT_NEAR(s22, stretch * stretch * closed.stress(1, 1), 2e-4 * std::abs(s22)) << stretch;
    EXPECT_GT(s11, s22);  // fibres at 43 deg from circumferential: stiffer circumferentially
  }
}

INSTANTIATE_TEST_SUITE_P(SingleElementAndIrregularBlock, UniaxialStress, ::testing::Values(0.0, 0.25));

TEST(HexahedronPatch, LinearFieldsAreExactAndRigidMotionIsFree) {
  const Mesh mesh = box_mesh(0.003, 0.002, 0.001, 3, 3, 3, 0.25);
  const HexahedronModel model = model_of(mesh);
  std::mt19937 rng(5);
  for (const auto& material : all_laws(5e6)) {
    // Linear field: every element sees F = A, interior nodes carry no force, no hourglass energy.
    const Eigen::Matrix3d A = random_stretch(rng, 0.05);
    const Assembled a = assemble(model, material, deformed(mesh, A, Eigen::Vector3d(1e-3, -2e-3, 5e-4)));
    double boundary = 0, interior = 0;
    for (Eigen::Index n = 0; n < mesh.nodes.cols(); ++n) {
      const Eigen::Vector3d X = mesh.nodes.col(n);
      const bool inside = X.x() > 1e-9 && X.x() < 0.003 - 1e-9 && X.y() > 1e-9 && X.y() < 0.002 - 1e-9 &&
                          X.z() > 1e-9 && X.z() < 0.001 - 1e-9;
      (inside ? interior : boundary) = std::max(inside ? interior : boundary, a.force.col(n).norm());
    }
    EXPECT_GT(boundary, 0.0);
    EXPECT_LT(interior, 1e-9 * boundary) << "law " << material.index();
    EXPECT_LT(a.hourglass_energy, 1e-12 * a.strain_energy);
    for (const auto& el : model.elements) {
      EXPECT_LT((hex_kinematics(el, deformed(mesh, A)).F - A).norm(), 1e-12);
    }
    // Rigid rotation and translation: no energy, no force.
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    const Assembled r = assemble(model, material, deformed(mesh, R, Eigen::Vector3d(0.01, 0.02, -0.03)));
    EXPECT_LT(r.force.cwiseAbs().maxCoeff(), 1e-9 * boundary);
    EXPECT_LT(std::abs(r.strain_energy) + r.hourglass_energy, 1e-12);
  }
}

TEST(HexahedronElement, ForceIsTheGradientOfTheEnergy) {
  // For fixed hourglass moduli the element force is the exact gradient of V0 W(F-bar) plus the
  // hourglass energy (frame rotation included); checked with the hourglass off and on.
  const Mesh mesh = box_mesh(0.002, 0.002, 0.001, 2, 2, 1, 0.0);
  Mesh distorted = mesh;
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-0.15e-3, 0.15e-3);
  for (Eigen::Index n = 0; n < distorted.nodes.cols(); ++n) distorted.nodes.col(n) += Eigen::Vector3d(u(rng), u(rng), 0.3 * u(rng));
  const HexahedronModel model = model_of(distorted);
  for (const HexModuli none : {HexModuli{0.0, 0.0}, HexModuli{3e6, 1e6, 0.4}})
  for (const auto& material : all_laws(1e6)) {
    Eigen::Matrix3Xd x = deformed(distorted, random_stretch(rng, 0.08));
    for (Eigen::Index n = 0; n < x.cols(); ++n) x.col(n) += Eigen::Vector3d(u(rng), u(rng), u(rng)) * 0.3;
    const Assembled a = assemble(model, material, x, &none);
    Eigen::Matrix3Xd direction = Eigen::Matrix3Xd::NullaryExpr(3, x.cols(), [&] { return u(rng) / 0.15e-3; });
    const double h = 1e-9;
    const auto energy = [&](const Eigen::Matrix3Xd& y) {
      const Assembled b = assemble(model, material, y, &none);
      return b.strain_energy + b.hourglass_energy;
    };
    const double dE = (energy(x + h * direction) - energy(x - h * direction)) / (2 * h);
    const double expected = a.force.cwiseProduct(direction).sum();
    EXPECT_NEAR(dE, expected, 1e-6 * a.force.norm() * direction.norm())
        << "law " << material.index() << " hourglass modulus " << none.shear;
  }
}

TEST(HexahedronHourglass, RectangularBrickBendsExactlyAndEveryModeIsResisted) {
  // Brick 4 x 2 x 0.5 mm (half-lengths a, b, c), SVK nu = 0 (E' = E): the bending field
  // u_x = k x z, u_z = -k x^2 / 2 stores E' V k^2 c^2 / 6 in the hourglass and nothing at the centre.
  const double a = 2e-3, b = 1e-3, c = 0.25e-3, E = 1e6;
  Mesh mesh = box_mesh(2 * a, 2 * b, 2 * c, 1, 1, 1);
  mesh.nodes.colwise() -= Eigen::Vector3d(a, b, c);
  const HexahedronModel model = model_of(mesh);
  const SolidMaterial material = SolidSaintVenantKirchhoff(E, 0.0);
  const double kappa_bend = 1e-3 / (a * c);  // small: linear regime
  Eigen::Matrix3Xd x = mesh.nodes;
  for (Eigen::Index n = 0; n < x.cols(); ++n) {
    const Eigen::Vector3d X = mesh.nodes.col(n);
    x(0, n) += kappa_bend * X.x() * X.z();
    x(2, n) -= 0.5 * kappa_bend * X.x() * X.x();
  }
  const Assembled bent = assemble(model, material, x);
  const double V = 8 * a * b * c;
  const double exact = E * V * kappa_bend * kappa_bend * c * c / 6.0;
  EXPECT_NEAR(bent.hourglass_energy, exact, 1e-3 * exact);
  EXPECT_LT(bent.strain_energy, 1e-3 * exact);

  // Every one of the 12 hourglass modes (3 components x 4 patterns) is resisted: f . u > 0.
  const double signs[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                              {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  for (int mode = 0; mode < 4; ++mode) {
    for (int comp = 0; comp < 3; ++comp) {
      Eigen::Matrix3Xd u = Eigen::Matrix3Xd::Zero(3, 8);
      for (int n = 0; n < 8; ++n) {
        const double* s = signs[n];
        const double h = mode == 0 ? s[0] * s[1] : mode == 1 ? s[1] * s[2] : mode == 2 ? s[2] * s[0] : s[0] * s[1] * s[2];
        u(comp, mesh.hexahedra[0][static_cast<std::size_t>(n)]) = 1e-6 * h;
      }
      const Assembled r = assemble(model, material, mesh.nodes + u);
      EXPECT_GT(r.force.cwiseProduct(u).sum(), 0.0) << "mode " << mode << " component " << comp;
      EXPECT_GT(r.hourglass_energy, 1e3 * std::abs(r.strain_energy)) << "mode " << mode << " component " << comp;
    }
  }
}

TEST(HexahedronFields, SurfaceStrainOfABentBrickAndStressOfAStretchedOne) {
  // Pure bending by curvature k of a brick 2c thick: the surface log strain is ~ k c (centre ~ 0);
  // uniaxial strain: every point reports log(stretch).
  const double a = 2e-3, c = 0.25e-3, k = 20.0;
  Mesh mesh = box_mesh(2 * a, 2 * a, 2 * c, 1, 1, 1);
  mesh.nodes.colwise() -= Eigen::Vector3d(a, a, c);
  HexahedronSolver solver(model_of(mesh), SolidSaintVenantKirchhoff(1e6, 0.0));
  HexahedronState state = solver.state();
  for (Eigen::Index n = 0; n < 8; ++n) {
    const Eigen::Vector3d X = mesh.nodes.col(n);
    state.position.col(n) = X + Eigen::Vector3d(k * X.x() * X.z(), 0.0, -0.5 * k * X.x() * X.x());
  }
  solver.restore(state);
  Eigen::VectorXd stress, strain;
  solver.surface_fields(stress, strain);
  EXPECT_NEAR(strain(0), k * c, 0.05 * k * c);
  EXPECT_NEAR(stress(0), 1e6 * k * c, 0.1 * 1e6 * k * c);
  solver.element_fields(stress, strain);
  EXPECT_LT(strain(0), 0.01 * k * c);  // the centre does not see the bending

  for (Eigen::Index n = 0; n < 8; ++n) state.position.col(n) = mesh.nodes.col(n).cwiseProduct(Eigen::Vector3d(1.1, 1, 1));
  solver.restore(state);
  solver.element_fields(stress, strain);
  EXPECT_NEAR(strain(0), std::log(1.1), 1e-12);
  // SVK nu = 0, uniaxial strain: sigma11 = lambda S11 lambda / J = E E11 lambda.
  EXPECT_NEAR(stress(0), 1e6 * 0.5 * (1.21 - 1) * 1.1, 1e-6);
  solver.surface_fields(stress, strain);
  EXPECT_NEAR(strain(0), std::log(1.1), 1e-12);
}

TEST(HexahedronLoads, PressureFacesCarryPressureTimesAreaAndPickTheOuterSurface) {
  const Mesh mesh = box_mesh(0.004, 0.002, 0.0005, 4, 2, 2);
  const auto faces = ventricular_faces(mesh);
  EXPECT_EQ(faces.size(), 8u);  // the bottom layer only
  HexahedronSolver solver(model_of(mesh), SolidNeoHookean(1e5, 1e7));
  solver.set_pressure([](double) { return 1000.0; }, faces);
  solver.advance_window(0.0);
  // Not moved yet: no internal force; the first step's external force is dp * area along +z.
  solver.advance_window(1e-9);
  const Eigen::Vector3d total = solver.state().external_force.rowwise().sum();
  EXPECT_NEAR(total.z(), 1000.0 * 0.004 * 0.002, 1e-6);
  EXPECT_NEAR(total.head<2>().norm(), 0.0, 1e-9);
  for (const auto n : mesh.node_sets.at("z1")) EXPECT_EQ(solver.state().external_force.col(n).norm(), 0.0);
}

TEST(HexahedronModelBuild, BadMeshesAreNamed) {
  Mesh mesh = box_mesh(1, 1, 1, 1, 1, 1);
  for (int a = 0; a < 4; ++a) std::swap(mesh.hexahedra[0][a], mesh.hexahedra[0][a + 4]);  // inside out
  try {
    model_of(mesh);
    FAIL() << "inverted brick accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("/mesh/hexahedra[0]"), std::string::npos) << e.what();
  }
  Mesh no_bricks = box_mesh(1, 1, 1, 1, 1, 1);
  no_bricks.hexahedra.clear();
  EXPECT_THROW(model_of(no_bricks), std::invalid_argument);
}

}  // namespace
}  // namespace valvefsi::solid
