#include "valvefsi/solid/hexahedron_elements.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>
#include <omp.h>

#include "valvefsi/solid/material_error.hpp"

namespace valvefsi::solid {
namespace {
constexpr std::array<std::array<double, 2>, 4> kFaceSigns{{{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}};
}  // namespace

HexahedronModel build_hexahedron_model(const Mesh& mesh, const HexahedronModelOptions& options,
                                       const std::string& source) {
  if (mesh.hexahedra.empty()) {
    throw std::invalid_argument(fmt::format("{}: /mesh/hexahedra is missing or empty", source));
  }
  if (!(options.density > 0.0)) {
    throw std::invalid_argument(fmt::format("{}: density = {}: allowed > 0", source, options.density));
  }
  const auto num = static_cast<Eigen::Index>(mesh.hexahedra.size());
  if (mesh.hexahedron_circumferential.cols() != num || mesh.hexahedron_radial.cols() != num) {
    throw std::invalid_argument(fmt::format(
        "{}: /mesh/hexahedron_axes has {} circumferential and {} radial axes for {} hexahedra", source,
        mesh.hexahedron_circumferential.cols(), mesh.hexahedron_radial.cols(), num));
  }
  HexahedronModel model;
  model.density = options.density;
  model.reference_positions = mesh.nodes;
  model.nodal_mass = Eigen::VectorXd::Zero(mesh.nodes.cols());
  model.elements.reserve(mesh.hexahedra.size());
  for (Eigen::Index e = 0; e < num; ++e) {
    const auto& nodes = mesh.hexahedra[static_cast<std::size_t>(e)];
    for (const std::int64_t n : nodes) {
      if (n < 0 || n >= mesh.nodes.cols()) {
        throw std::invalid_argument(fmt::format("{}: /mesh/hexahedra[{}] has node {}: allowed 0..{}", source, e, n,
                                                mesh.nodes.cols() - 1));
      }
    }
    try {
      model.elements.push_back(make_hex_element(nodes, mesh.nodes, mesh.hexahedron_circumferential.col(e),
                                                mesh.hexahedron_radial.col(e)));
    } catch (const std::invalid_argument& ex) {
      throw std::invalid_argument(fmt::format("{}: /mesh/hexahedra[{}]: {}", source, e, ex.what()));
    }
    for (const std::int64_t n : nodes) model.nodal_mass(n) += options.density * model.elements.back().volume / 8.0;
  }
  model.fixed.assign(static_cast<std::size_t>(mesh.nodes.cols()), 0);
  for (const std::int64_t n : options.fixed_nodes) {
    if (n < 0 || n >= mesh.nodes.cols()) {
      throw std::invalid_argument(fmt::format("{}: fixed node {}: allowed 0..{}", source, n, mesh.nodes.cols() - 1));
    }
    model.fixed[static_cast<std::size_t>(n)] = 1;
  }
  return model;
}

std::vector<PressureFace> ventricular_faces(const Mesh& mesh, const std::vector<std::int64_t>& elements) {
  std::set<std::array<std::int64_t, 4>> aortic;
  for (const auto& h : mesh.hexahedra) {
    std::array<std::int64_t, 4> top{h[4], h[5], h[6], h[7]};
    std::sort(top.begin(), top.end());
    aortic.insert(top);
  }
  std::vector<std::int64_t> chosen = elements;
  if (chosen.empty()) {
    chosen.resize(mesh.hexahedra.size());
    for (std::size_t e = 0; e < chosen.size(); ++e) chosen[e] = static_cast<std::int64_t>(e);
  }
  std::vector<PressureFace> faces;
  for (const std::int64_t e : chosen) {
    const auto& h = mesh.hexahedra.at(static_cast<std::size_t>(e));
    std::array<std::int64_t, 4> bottom{h[0], h[1], h[2], h[3]};
    std::array<std::int64_t, 4> key = bottom;
    std::sort(key.begin(), key.end());
    if (aortic.count(key) == 0) faces.push_back(bottom);
  }
  return faces;
}

HexahedronElements::HexahedronElements(HexahedronModel model, SolidMaterial material)
    : model_(std::move(model)), material_(std::move(material)) {
  moduli_.assign(model_.elements.size(), hex_moduli(shear_modulus(material_), bulk_modulus(material_)));
}

void HexahedronElements::set_pressure_faces(std::vector<PressureFace> faces) {
  for (const auto& face : faces) {
    for (const std::int64_t n : face) {
      if (n < 0 || n >= model_.reference_positions.cols()) {
        throw std::invalid_argument(fmt::format("solid: pressure face node {} does not exist", n));
      }
    }
  }
  pressure_faces_ = std::move(faces);
}

InternalForceResult HexahedronElements::internal_force(const Eigen::Matrix3Xd& x, bool estimate_step,
                                                       Eigen::Matrix3Xd& out, Eigen::Matrix3Xd* hourglass) {
  const auto num_elements = static_cast<std::int64_t>(model_.elements.size());
  const double density = model_.density;
  return std::visit(
      [&](const auto& law) {
        return accumulate_element_forces(
            "hexahedron", num_elements, [](std::int64_t) {},
            [&](std::int64_t e, Eigen::Matrix3Xd& f, Eigen::Matrix3Xd& fh) {
              const auto ue = static_cast<std::size_t>(e);
              const HexElementResult r =
                  hex_element_force(model_.elements[ue], law, x, density, moduli_[ue], estimate_step, f, &fh);
              // The element's critical step 2 / omega (the same value and element as 2 / sqrt of the
              // largest omega^2).
              const double step = estimate_step && r.omega2 > 0.0 ? 2.0 / std::sqrt(r.omega2)
                                                                  : std::numeric_limits<double>::infinity();
              return ElementContribution{r.strain_energy, r.hourglass_energy, step};
            },
            out, hourglass);
      },
      material_);
}

void HexahedronElements::add_pressure_force(const Eigen::Matrix3Xd& x, double dp, Eigen::Matrix3Xd& f) const {
  const double g = 1.0 / std::sqrt(3.0);
  for (const auto& face : pressure_faces_) {
    // Consistent load of the bilinear face: f_a = dp int N_a (x,xi x x,eta) dxi deta (2x2 Gauss, exact).
    for (const auto& gp : kFaceSigns) {
      const double xi = g * gp[0], eta = g * gp[1];
      Eigen::Vector3d dxi = Eigen::Vector3d::Zero(), deta = Eigen::Vector3d::Zero();
      std::array<double, 4> N{};
      for (int a = 0; a < 4; ++a) {
        const auto& s = kFaceSigns[static_cast<std::size_t>(a)];
        N[static_cast<std::size_t>(a)] = 0.25 * (1 + s[0] * xi) * (1 + s[1] * eta);
        dxi += 0.25 * s[0] * (1 + s[1] * eta) * x.col(face[static_cast<std::size_t>(a)]);
        deta += 0.25 * s[1] * (1 + s[0] * xi) * x.col(face[static_cast<std::size_t>(a)]);
      }
      const Eigen::Vector3d area = dp * dxi.cross(deta);
      for (int a = 0; a < 4; ++a) f.col(face[static_cast<std::size_t>(a)]) += N[static_cast<std::size_t>(a)] * area;
    }
  }
}

void HexahedronElements::element_fields(const Eigen::Matrix3Xd& x, Eigen::VectorXd& max_principal_stress,
                                        Eigen::VectorXd& max_principal_log_strain) const {
  fields(x, max_principal_stress, max_principal_log_strain, false);
}

void HexahedronElements::surface_fields(const Eigen::Matrix3Xd& x, Eigen::VectorXd& max_principal_stress,
                                        Eigen::VectorXd& max_principal_log_strain) const {
  fields(x, max_principal_stress, max_principal_log_strain, true);
}

void HexahedronElements::fields(const Eigen::Matrix3Xd& x, Eigen::VectorXd& max_principal_stress, Eigen::VectorXd& max_principal_log_strain,
                              bool surfaces) const {
  // Centre: the 3D law at the F-bar F (the integration point). Surfaces: the centres of the faces
  // zeta = -1, +1, where the full trilinear gradient gives the in-plane C2 in the material frame,
  // evaluated with the sheet's plane-stress law (sigma33 = 0, as the shell's outer thickness points).
  static const std::array<Eigen::Matrix<double, 3, 8>, 2> faces{hex_shape_derivatives(Eigen::Vector3d(0, 0, -1)),
                                                                hex_shape_derivatives(Eigen::Vector3d(0, 0, 1))};
  const Material sheet = plane_stress_form(material_);
  const auto num_elements = static_cast<Eigen::Index>(model_.elements.size());
  max_principal_stress.resize(num_elements);
  max_principal_log_strain.resize(num_elements);
  std::visit(
      [&](const auto& law) {
#pragma omp parallel for schedule(static) if (num_elements >= kMinElementsForThreads)
        for (Eigen::Index e = 0; e < num_elements; ++e) {
          try {
            const HexElement& el = model_.elements[static_cast<std::size_t>(e)];
            const HexKinematics k = hex_kinematics(el, x);
            Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
            eig.computeDirect(hex_cauchy_stress(el, law, k.F), Eigen::EigenvaluesOnly);
            double stress = eig.eigenvalues().maxCoeff();
            eig.computeDirect(k.F.transpose() * k.F, Eigen::EigenvaluesOnly);
            double strain = 0.5 * std::log(eig.eigenvalues().maxCoeff());
            if (!surfaces) {
              max_principal_stress(e) = stress;
              max_principal_log_strain(e) = strain;
              continue;
            }
            stress = strain = -std::numeric_limits<double>::infinity();
            Eigen::Matrix<double, 3, 8> X;
            for (int a = 0; a < 8; ++a) X.col(a) = model_.reference_positions.col(el.nodes[static_cast<std::size_t>(a)]);
            const Eigen::Matrix<double, 3, 2> in_plane = el.material_axes.leftCols<2>();
            for (const auto& dN : faces) {
              const Eigen::Matrix<double, 3, 8> gradient = (X * dN.transpose()).inverse().transpose() * dN;
              const Eigen::Matrix<double, 3, 2> F2 = k.x * gradient.transpose() * in_plane;
              const Eigen::Matrix2d C2 = F2.transpose() * F2;
              const PlaneStressResponse r = plane_stress(sheet, C2, false);
              // Cauchy stress F2 S F2^T / J shares its non-zero eigenvalues with S C2 / J, J = lambda3 sqrt(det C2).
              const Eigen::Matrix2d M = r.stress * C2 / (r.thickness_stretch * std::sqrt(C2.determinant()));
              const double half_trace = 0.5 * M.trace();
              stress = std::max(stress, half_trace + std::sqrt(std::max(0.0, half_trace * half_trace - M.determinant())));
              const double c_half = 0.5 * C2.trace();
              strain = std::max(strain, 0.5 * std::log(c_half + std::sqrt(std::max(0.0, c_half * c_half - C2.determinant()))));
            }
            max_principal_stress(e) = stress;
            max_principal_log_strain(e) = strain;
          } catch (const MaterialStateError&) {
            max_principal_stress(e) = std::numeric_limits<double>::quiet_NaN();
            max_principal_log_strain(e) = std::numeric_limits<double>::quiet_NaN();
          }
        }
      },
      material_);
}

}  // namespace valvefsi::solid
