#pragma once
// The 8-node hexahedron with one-point (uniform-strain) integration, mean-dilatation F-bar and
// physical stiffness-type hourglass control (docs/solid_fe-hexahedron.md).
//   * Deformation: Fbar = sum_a x_a (x) Bbar_a, Bbar_a = (1/V0) int grad_X N_a dV (the
//     Flanagan-Belytschko mean gradient, exact for linear fields), then F = (v/V0 / det Fbar)^(1/3) Fbar
//     so that det F is the element's exact current volume ratio (mean dilatation, no volumetric locking).
//   * Forces are the exact gradient of V0 W(F): f_a = V0 [ (r P - tau Fbar^-T) Bbar_a + tau/v dv/dx_a ],
//     r = (v/(V0 det Fbar))^(1/3), tau = P:F/3.
//   * Hourglass: q_alpha = sum_a x_a gamma_alpha,a (gamma orthogonal to linear fields), energy
//     1/2 sum_alpha sum_i k_i,alpha (R^T q_alpha)_i^2 in the element's current natural frame R, with
//     k calibrated so that a rectangular brick bends exactly (bending modulus E' = 4 mu (3K + mu)/(3K + 4 mu),
//     the plane-strain E/(1 - nu^2): 4 mu when incompressible), mu and K the small-strain moduli.
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

#include "valvefsi/solid/hexahedron_material.hpp"

namespace valvefsi::solid {

// Reference data of one brick, computed once.
struct HexElement {
  std::array<std::int64_t, 8> nodes{};
  double volume = 0.0;                          // V0 (m^3)
  Eigen::Matrix<double, 3, 8> mean_gradient;    // Bbar_a = (1/V0) int grad_X N_a dV, columns a
  Eigen::Matrix<double, 4, 8> hourglass;        // gamma_alpha,a, rows alpha = xi eta, eta zeta, zeta xi, xi eta zeta
  Eigen::Matrix3d material_axes;                // columns e1 circumferential, e2 radial, e3 normal (reference)
  Eigen::Matrix<double, 3, 4> bending_factor;   // k_i,alpha per unit bending modulus E' (m^3 / m^2)
  Eigen::Matrix<double, 3, 4> shear_factor;     // k_i,alpha per unit shear modulus
  Eigen::Vector4d hourglass_norm2;              // |gamma_alpha|^2
  // Poisson coupling of the two bending modes whose normal strains vary along natural axis m
  // (plate energy 2 nu eps_x eps_y): sqrt of the product of their bending factors.
  Eigen::Vector3d coupling_factor = Eigen::Vector3d::Zero();
};

// The two (component i, mode alpha) bending modes coupled for each varying axis m = xi, eta, zeta.
inline constexpr std::array<std::array<std::array<int, 2>, 2>, 3> kCoupledBendingModes{
    {{{{1, 0}, {2, 2}}}, {{{0, 0}, {2, 1}}}, {{{0, 2}, {1, 1}}}}};

// Moduli an element's hourglass control uses: the material's small-strain values, kept fixed so
// that the hourglass forces stay conservative (a modulus that follows the state, updated every
// few steps, pumped energy into a vibrating MHGO cantilever: 40x its initial energy in 10 ms).
struct HexModuli {
  double bending = 0.0;  // E' (Pa)
  double shear = 0.0;    // mu (Pa)
  double poisson = 0.0;  // nu, couples the bending modes
};

// Natural coordinates of the nodes: 0-3 the bottom face (zeta = -1) counter-clockwise seen from +zeta.
inline constexpr std::array<std::array<double, 3>, 8> kHexNodeSigns{{{-1, -1, -1}, {1, -1, -1}, {1, 1, -1},
                                                                     {-1, 1, -1}, {-1, -1, 1}, {1, -1, 1},
                                                                     {1, 1, 1}, {-1, 1, 1}}};

// dN_a/dxi_k (rows k, columns a) at natural point p.
Eigen::Matrix<double, 3, 8> hex_shape_derivatives(const Eigen::Vector3d& p);

// Exact volume of the trilinear brick with nodal positions x (columns) and dv/dx_a (2x2x2 Gauss is exact).
double hex_volume_and_gradient(const Eigen::Matrix<double, 3, 8>& x, Eigen::Matrix<double, 3, 8>* gradient);

// Builds an element's reference data. Throws std::invalid_argument when its volume is not positive.
HexElement make_hex_element(const std::array<std::int64_t, 8>& nodes, const Eigen::Matrix3Xd& reference,
                            const Eigen::Vector3d& circumferential, const Eigen::Vector3d& radial);

// Orthonormal natural frame of a brick from its centre Jacobian columns g_xi, g_eta, g_zeta:
// e1 along g_xi, e3 normal to (g_xi, g_eta), e2 = e3 x e1.
inline Eigen::Matrix3d hex_natural_frame(const Eigen::Matrix3d& g) {
  Eigen::Matrix3d R;
  R.col(0) = g.col(0).normalized();
  R.col(2) = g.col(0).cross(g.col(1)).normalized();
  R.col(1) = R.col(2).cross(R.col(0));
  return R;
}

// E' of a rectangular brick's bending hourglass mode (plane-strain E/(1 - nu^2) in K and mu).
inline double hex_bending_modulus(double shear_modulus, double bulk_modulus) {
  return 4.0 * shear_modulus * (3.0 * bulk_modulus + shear_modulus) / (3.0 * bulk_modulus + 4.0 * shear_modulus);
}

inline HexModuli hex_moduli(double shear_modulus, double bulk_modulus) {
  return {hex_bending_modulus(shear_modulus, bulk_modulus), shear_modulus,
          (3.0 * bulk_modulus - 2.0 * shear_modulus) / (2.0 * (3.0 * bulk_modulus + shear_modulus))};
}

// The uniform deformation of a brick: Fbar, the F-bar F, and the volume data.
struct HexKinematics {
  Eigen::Matrix<double, 3, 8> x;
  Eigen::Matrix3d Fbar;
  Eigen::Matrix3d F;          // F-bar: det F = v / V0
  Eigen::Matrix<double, 3, 8> volume_gradient;  // dv/dx_a
  double volume = 0.0;        // current v
  double scale = 1.0;         // r = (v / (V0 det Fbar))^(1/3)
};

inline HexKinematics hex_kinematics(const HexElement& el, const Eigen::Matrix3Xd& positions) {
  HexKinematics k;
  for (int a = 0; a < 8; ++a) k.x.col(a) = positions.col(el.nodes[static_cast<std::size_t>(a)]);
  k.Fbar = k.x * el.mean_gradient.transpose();
  k.volume = hex_volume_and_gradient(k.x, &k.volume_gradient);
  const double det_bar = k.Fbar.determinant();
  if (!(k.volume > 0.0) || !(det_bar > 0.0)) {
    throw MaterialStateError(fmt::format("brick inverted: volume ratio {:g}, det(Fbar) = {:g}",
                                         k.volume / el.volume, det_bar));
  }
  k.scale = std::cbrt(k.volume / (el.volume * det_bar));
  k.F = k.scale * k.Fbar;
  return k;
}

// Second Piola-Kirchhoff stress (global reference axes) and energy density at F.
template <class Law>
SolidResponse hex_material_response(const HexElement& el, const Law& law, const Eigen::Matrix3d& F) {
  const Eigen::Matrix3d& Q = el.material_axes;
  SolidResponse r = law.response(Q.transpose() * (F.transpose() * F) * Q);
  r.stress = Q * r.stress * Q.transpose();
  return r;
}

template <class Law>
Eigen::Matrix3d hex_cauchy_stress(const HexElement& el, const Law& law, const Eigen::Matrix3d& F) {
  const SolidResponse r = hex_material_response(el, law, F);
  return F * r.stress * F.transpose() / F.determinant();
}

struct HexElementResult {
  double strain_energy = 0.0;     // V0 W (J)
  double hourglass_energy = 0.0;  // 1/2 sum k q^2 (J)
  double omega2 = 0.0;            // upper bound of the element's highest frequency squared (1/s^2), if asked
  HexModuli moduli;               // the moduli used
};

// Adds the element's internal force (hyperelastic plus hourglass) to `forces` (the hourglass
// part also to `hourglass_forces` when given) and, with `estimate`, bounds the element's highest
// frequency:
//   omega^2 <= 8/(rho V0) [ v M sum_a |b_a|^2 + max_i sum_alpha k_i,alpha |gamma_alpha|^2 ],
// (Flanagan-Belytschko), b_a = dv/dx_a / v, M the largest wave modulus of the state measured
// by finite differences of the Cauchy stress along the element's axes and in-plane diagonals.
template <class Law>
HexElementResult hex_element_force(const HexElement& el, const Law& law, const Eigen::Matrix3Xd& positions,
                                   double density, const HexModuli& moduli, bool estimate, Eigen::Matrix3Xd& forces,
                                   Eigen::Matrix3Xd* hourglass_forces = nullptr) {
  const HexKinematics k = hex_kinematics(el, positions);
  const SolidResponse r = hex_material_response(el, law, k.F);
  const Eigen::Matrix3d P = k.F * r.stress;
  const double tau = P.cwiseProduct(k.F).sum() / 3.0;
  const Eigen::Matrix3d Fbar_inverse_t = k.Fbar.inverse().transpose();
  const Eigen::Matrix3d G = k.scale * P - tau * Fbar_inverse_t;
  Eigen::Matrix<double, 3, 8> f = el.volume * (G * el.mean_gradient + (tau / k.volume) * k.volume_gradient);

  HexElementResult result;
  result.strain_energy = el.volume * r.energy;

  static const Eigen::Matrix<double, 3, 8> centre_derivatives = hex_shape_derivatives(Eigen::Vector3d::Zero());
  const Eigen::Matrix3d g = k.x * centre_derivatives.transpose();
  const Eigen::Matrix3d R = hex_natural_frame(g);
  if (estimate) {
    // Wave moduli by forward differences of the Cauchy stress under small uniaxial strains.
    const Eigen::Matrix3d sigma = k.F * r.stress * k.F.transpose() / k.F.determinant();
    const std::array<Eigen::Vector3d, 5> directions{R.col(0), R.col(1), R.col(2),
                                                   (R.col(0) + R.col(1)).normalized(),
                                                   (R.col(0) - R.col(1)).normalized()};
    constexpr double h = 1e-6;
    double M = 0.0, tension = 0.0;
    for (const auto& n : directions) {
      const Eigen::Matrix3d Fp = (Eigen::Matrix3d::Identity() + h * n * n.transpose()) * k.F;
      const double s0 = n.dot(sigma * n);
      M = std::max(M, (n.dot(hex_cauchy_stress(el, law, Fp) * n) - s0) / h);
      tension = std::max(tension, s0);
    }
    result.moduli = moduli;
    double hourglass_stiffness = 0.0;
    for (int i = 0; i < 3; ++i) {
      double sum = 0.0;
      for (int a = 0; a < 4; ++a) {
        sum += (moduli.bending * el.bending_factor(i, a) + moduli.shear * el.shear_factor(i, a)) * el.hourglass_norm2(a);
      }
      sum += moduli.bending * std::abs(moduli.poisson) * el.coupling_factor.maxCoeff() * el.hourglass_norm2.maxCoeff();
      hourglass_stiffness = std::max(hourglass_stiffness, sum);
    }
    result.omega2 = 8.0 / (density * el.volume) *
                    ((M + tension) * k.volume_gradient.squaredNorm() / k.volume + hourglass_stiffness);
  }

  // Hourglass forces: the exact gradient of the hourglass energy, including the turn of the
  // natural frame R(g_xi, g_eta) with the nodes (without it the forces are not conservative and
  // pump energy into a bending brick that rotates).
  Eigen::Matrix<double, 3, 8> f_hourglass = Eigen::Matrix<double, 3, 8>::Zero();
  Eigen::Matrix3d w = Eigen::Matrix3d::Zero();  // column i: sum_alpha T_i,alpha q_alpha
  Eigen::Matrix<double, 3, 4> q, q_local, T;      // hourglass vectors, local, generalised stresses
  for (int a = 0; a < 4; ++a) {
    q.col(a) = k.x * el.hourglass.row(a).transpose();
    q_local.col(a) = R.transpose() * q.col(a);
    T.col(a) = (moduli.bending * el.bending_factor.col(a) + moduli.shear * el.shear_factor.col(a))
                   .cwiseProduct(q_local.col(a));
  }
  for (int m = 0; m < 3; ++m) {
    const auto& [first, second] = kCoupledBendingModes[static_cast<std::size_t>(m)];
    const double c = moduli.bending * moduli.poisson * el.coupling_factor(m);
    T(first[0], first[1]) += c * q_local(second[0], second[1]);
    T(second[0], second[1]) += c * q_local(first[0], first[1]);
  }
  for (int a = 0; a < 4; ++a) {
    result.hourglass_energy += 0.5 * T.col(a).dot(q_local.col(a));
    f_hourglass += (R * T.col(a)) * el.hourglass.row(a);
    w += q.col(a) * T.col(a).transpose();
  }
  {
    const auto skew = [](const Eigen::Vector3d& v) {
      Eigen::Matrix3d m;
      m << 0, -v(2), v(1), v(2), 0, -v(0), -v(1), v(0), 0;
      return m;
    };
    const Eigen::Vector3d e1 = R.col(0), e3 = R.col(2);
    const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d A1 = (I - e1 * e1.transpose()) / g.col(0).norm();
    const Eigen::Matrix3d A3 = (I - e3 * e3.transpose()) / g.col(0).cross(g.col(1)).norm();
    const Eigen::Matrix3d de3_dg1 = -A3 * skew(g.col(1)), de3_dg2 = A3 * skew(g.col(0));
    const Eigen::Matrix3d de2_dg1 = -skew(e1) * de3_dg1 + skew(e3) * A1, de2_dg2 = -skew(e1) * de3_dg2;
    const Eigen::Vector3d G1 = A1 * w.col(0) + de2_dg1.transpose() * w.col(1) + de3_dg1.transpose() * w.col(2);
    const Eigen::Vector3d G2 = de2_dg2.transpose() * w.col(1) + de3_dg2.transpose() * w.col(2);
    f_hourglass += G1 * centre_derivatives.row(0) + G2 * centre_derivatives.row(1);
  }
  f += f_hourglass;
  for (int a = 0; a < 8; ++a) forces.col(el.nodes[static_cast<std::size_t>(a)]) += f.col(a);
  if (hourglass_forces != nullptr) {
    for (int a = 0; a < 8; ++a) hourglass_forces->col(el.nodes[static_cast<std::size_t>(a)]) += f_hourglass.col(a);
  }
  return result;
}

}  // namespace valvefsi::solid
