#include "valvefsi/solid/hexahedron_element.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

namespace valvefsi::solid {
namespace {

// Hourglass base vectors h_alpha,a = xi eta, eta zeta, zeta xi, xi eta zeta at the nodes.
Eigen::Matrix<double, 4, 8> hourglass_base() {
  Eigen::Matrix<double, 4, 8> h;
  for (int a = 0; a < 8; ++a) {
    const auto& s = kHexNodeSigns[static_cast<std::size_t>(a)];
    h(0, a) = s[0] * s[1];
    h(1, a) = s[1] * s[2];
    h(2, a) = s[2] * s[0];
    h(3, a) = s[0] * s[1] * s[2];
  }
  return h;
}

// The natural directions each of the first three modes varies along (xi eta -> {0, 1}, ...).
constexpr std::array<std::array<int, 2>, 3> kModePairs{{{0, 1}, {1, 2}, {2, 0}}};

const std::array<Eigen::Matrix<double, 3, 8>, 8>& gauss_derivatives() {
  static const std::array<Eigen::Matrix<double, 3, 8>, 8> table = [] {
    std::array<Eigen::Matrix<double, 3, 8>, 8> t;
    const double g = 1.0 / std::sqrt(3.0);
    for (int p = 0; p < 8; ++p) {
      const auto& s = kHexNodeSigns[static_cast<std::size_t>(p)];
      t[static_cast<std::size_t>(p)] = hex_shape_derivatives(Eigen::Vector3d(g * s[0], g * s[1], g * s[2]));
    }
    return t;
  }();
  return table;
}

}  // namespace

Eigen::Matrix<double, 3, 8> hex_shape_derivatives(const Eigen::Vector3d& p) {
  Eigen::Matrix<double, 3, 8> d;
  for (int a = 0; a < 8; ++a) {
    const auto& s = kHexNodeSigns[static_cast<std::size_t>(a)];
    const double fx = 1.0 + s[0] * p(0), fy = 1.0 + s[1] * p(1), fz = 1.0 + s[2] * p(2);
    d(0, a) = 0.125 * s[0] * fy * fz;
    d(1, a) = 0.125 * s[1] * fx * fz;
    d(2, a) = 0.125 * s[2] * fx * fy;
  }
  return d;
}

double hex_volume_and_gradient(const Eigen::Matrix<double, 3, 8>& x, Eigen::Matrix<double, 3, 8>* gradient) {
  // det J is at most quadratic in each natural coordinate: 2x2x2 Gauss (weights 1) is exact.
  double volume = 0.0;
  if (gradient != nullptr) gradient->setZero();
  for (const auto& dN : gauss_derivatives()) {
    const Eigen::Matrix3d J = x * dN.transpose();  // columns dx/dxi_k
    Eigen::Matrix3d cofactor;                      // d det J / d J
    cofactor.col(0) = J.col(1).cross(J.col(2));
    cofactor.col(1) = J.col(2).cross(J.col(0));
    cofactor.col(2) = J.col(0).cross(J.col(1));
    volume += J.col(0).dot(cofactor.col(0));
    if (gradient != nullptr) *gradient += cofactor * dN;
  }
  return volume;
}

HexElement make_hex_element(const std::array<std::int64_t, 8>& nodes, const Eigen::Matrix3Xd& reference,
                            const Eigen::Vector3d& circumferential, const Eigen::Vector3d& radial) {
  HexElement el;
  el.nodes = nodes;
  Eigen::Matrix<double, 3, 8> X;
  for (int a = 0; a < 8; ++a) X.col(a) = reference.col(nodes[static_cast<std::size_t>(a)]);
  Eigen::Matrix<double, 3, 8> volume_gradient;
  el.volume = hex_volume_and_gradient(X, &volume_gradient);
  if (!(el.volume > 0.0)) {
    throw std::invalid_argument(fmt::format(
        "hexahedron volume {:g} m^3 <= 0: nodes 0-3 must be the bottom face counter-clockwise seen from the "
        "top face 4-7", el.volume));
  }
  el.mean_gradient = volume_gradient / el.volume;

  // gamma_alpha = (h_alpha - Bbar^T X h_alpha) / 8: orthogonal to constant and linear fields.
  const Eigen::Matrix<double, 4, 8> h = hourglass_base();
  for (int a = 0; a < 4; ++a) {
    const Eigen::Matrix<double, 1, 8> row = h.row(a);
    el.hourglass.row(a) = 0.125 * (row - (X * row.transpose()).transpose() * el.mean_gradient);
    el.hourglass_norm2(a) = el.hourglass.row(a).squaredNorm();
  }

  // Calibration on a rectangular brick with half-lengths a_i (natural axis i): the mode u_i = d h
  // with i among the mode's directions bends, normal strain d xi_m / a_i, energy E' V d^2 / (6 a_i^2);
  // the warping modes (i not among them) keep the in-plane shear only, softened when i is the thin
  // direction (their transverse shear is cancelled by companion modes in a real plate twist).
  const Eigen::Matrix3d g = X * hex_shape_derivatives(Eigen::Vector3d::Zero()).transpose();
  const Eigen::Vector3d half{g.col(0).norm(), g.col(1).norm(), g.col(2).norm()};
  el.bending_factor.setZero();
  el.shear_factor.setZero();
  for (int m = 0; m < 3; ++m) {
    const auto [j, k] = kModePairs[static_cast<std::size_t>(m)];
    for (int i = 0; i < 3; ++i) {
      if (i == j || i == k) {
        el.bending_factor(i, m) = el.volume / (3.0 * half(i) * half(i));
      } else {
        const double longer = std::max(half(j), half(k)), shorter = std::min(half(j), half(k));
        // thin (2 - thin) -> 2 (a_i / shorter)^2 for a thin i: with it the three twist modes of a
        // plate store the exact twisting energy 2/3 mu V kappa_xy^2 c^2.
        const double thin = std::min(1.0, (half(i) / shorter) * (half(i) / shorter));
        el.shear_factor(i, m) = thin * (2.0 - thin) * el.volume / (3.0 * longer * longer);
      }
    }
  }
  for (int i = 0; i < 3; ++i) el.bending_factor(i, 3) = el.volume / (9.0 * half(i) * half(i));
  for (int m = 0; m < 3; ++m) {
    const auto& [first, second] = kCoupledBendingModes[static_cast<std::size_t>(m)];
    el.coupling_factor(m) = std::sqrt(el.bending_factor(first[0], first[1]) * el.bending_factor(second[0], second[1]));
  }

  // Material frame: e1 circumferential, e3 normal to (circumferential, radial), e2 = e3 x e1.
  const Eigen::Vector3d e1 = circumferential.normalized();
  const Eigen::Vector3d e3 = e1.cross(radial).normalized();
  if (!e1.allFinite() || !e3.allFinite()) {
    throw std::invalid_argument("hexahedron axes: circumferential and radial must be non-zero and not parallel");
  }
  el.material_axes.col(0) = e1;
  el.material_axes.col(1) = e3.cross(e1);
  el.material_axes.col(2) = e3;
  return el;
}

}  // namespace valvefsi::solid
