#include "valvefsi/solid/solid_interface.hpp"

#include <algorithm>
#include <array>
#include <set>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

namespace valvefsi::solid {
namespace {

// Mean thickness of the triangles around each node.
Eigen::VectorXd node_thickness(const Mesh& mesh) {
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(mesh.num_nodes()), count = Eigen::VectorXd::Zero(mesh.num_nodes());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (const auto n : mesh.triangles[t]) {
      sum(n) += mesh.triangle_thickness[t];
      count(n) += 1.0;
    }
  }
  return sum.cwiseQuotient(count.cwiseMax(1.0));
}

}  // namespace

void SolidInterface::nodal_forces(const Eigen::Matrix3Xd& interface_forces, std::int64_t mesh_nodes,
                                  Eigen::Matrix3Xd& out) const {
  if (interface_forces.cols() != static_cast<Eigen::Index>(nodes.size())) {
    throw std::invalid_argument(fmt::format("solid: {} interface forces received, the interface has {} nodes",
                                            interface_forces.cols(), nodes.size()));
  }
  if (out.cols() != mesh_nodes) out.resize(3, mesh_nodes);
  out.setZero();
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const auto col = static_cast<Eigen::Index>(k);
    if (dimension == 2) {
      // Force per unit depth on the strip: the pair carries force x depth, half each.
      Eigen::Vector3d f = interface_forces.col(col) * (0.5 * depth);
      f.z() = 0.0;
      out.col(nodes[k]) += f;
      out.col(partner[k]) += f;
    } else {
      out.col(nodes[k]) += interface_forces.col(col);
    }
  }
}

void SolidInterface::motion(const ShellState& state, Eigen::Matrix3Xd& positions_out,
                            Eigen::Matrix3Xd& velocities_out) const {
  const auto n = static_cast<Eigen::Index>(nodes.size());
  positions_out.resize(3, n);
  velocities_out.resize(3, n);
  for (Eigen::Index k = 0; k < n; ++k) {
    positions_out.col(k) = state.position.col(nodes[static_cast<std::size_t>(k)]);
    velocities_out.col(k) = state.velocity.col(nodes[static_cast<std::size_t>(k)]);
  }
  if (dimension == 2) {
    positions_out.row(2).setZero();
    velocities_out.row(2).setZero();
  }
}

SolidInterface surface_interface(const Mesh& mesh) {
  SolidInterface s;
  s.dimension = 3;
  s.nodes_per_cell = 3;
  const auto n = mesh.num_nodes();
  s.nodes.resize(static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i) s.nodes[static_cast<std::size_t>(i)] = i;
  s.positions = mesh.nodes;
  s.cells.resize(3, mesh.num_triangles());
  s.node_areas = Eigen::VectorXd::Zero(n);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const double area =
        0.5 * (mesh.nodes.col(tri[1]) - mesh.nodes.col(tri[0])).cross(mesh.nodes.col(tri[2]) - mesh.nodes.col(tri[0])).norm();
    for (int a = 0; a < 3; ++a) {
      s.cells(a, static_cast<Eigen::Index>(t)) = static_cast<int>(tri[a]);
      s.node_areas(tri[a]) += area / 3.0;
    }
  }
  s.node_thickness = node_thickness(mesh);
  return s;
}

SolidInterface strip_interface(const Mesh& mesh, const std::vector<StripTie>& ties, double depth,
                               const std::string& source) {
  SolidInterface s;
  s.dimension = 2;
  s.nodes_per_cell = 2;
  s.depth = depth;
  const Eigen::VectorXd thickness = node_thickness(mesh);
  std::set<std::pair<std::int64_t, std::int64_t>> edges;
  for (const auto& tri : mesh.triangles) {
    for (int a = 0; a < 3; ++a) {
      const auto p = tri[a], q = tri[(a + 1) % 3];
      edges.insert({std::min(p, q), std::max(p, q)});
    }
  }
  const auto n = static_cast<Eigen::Index>(ties.size());
  s.positions.resize(3, n);
  s.node_areas = Eigen::VectorXd::Zero(n);
  s.node_thickness.resize(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto& tie = ties[static_cast<std::size_t>(k)];
    s.nodes.push_back(tie.front);
    s.partner.push_back(tie.back);
    s.positions.col(k) = mesh.nodes.col(tie.front);
    s.positions(2, k) = 0.0;
    s.node_thickness(k) = thickness(tie.front);
  }
  std::vector<std::array<int, 2>> segments;
  for (Eigen::Index k = 0; k + 1 < n; ++k) {
    const auto a = ties[static_cast<std::size_t>(k)].front, b = ties[static_cast<std::size_t>(k + 1)].front;
    if (edges.count({std::min(a, b), std::max(a, b)}) == 0) continue;  // next leaflet starts
    segments.push_back({static_cast<int>(k), static_cast<int>(k + 1)});
    const double half = 0.5 * (s.positions.col(k + 1) - s.positions.col(k)).norm();
    s.node_areas(k) += half;
    s.node_areas(k + 1) += half;
  }
  if (segments.empty()) {
    throw std::invalid_argument(fmt::format("{}: node set strip_front has no two consecutive nodes joined by a "
                                            "triangle edge: no interface segments", source));
  }
  s.cells.resize(2, static_cast<Eigen::Index>(segments.size()));
  for (std::size_t c = 0; c < segments.size(); ++c) {
    s.cells(0, static_cast<Eigen::Index>(c)) = segments[c][0];
    s.cells(1, static_cast<Eigen::Index>(c)) = segments[c][1];
  }
  return s;
}

}  // namespace valvefsi::solid
