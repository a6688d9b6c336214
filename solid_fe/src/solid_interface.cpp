#include "valvefsi/solid/solid_interface.hpp"

#include <algorithm>
#include <array>
#include <set>
#include <stdexcept>
#include <utility>

#include <Eigen/Geometry>
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
    } else if (mid_surface_pairs) {
      // The mid-surface node moves as the pair's mean: half each keeps force and power equal.
      const Eigen::Vector3d f = 0.5 * interface_forces.col(col);
      out.col(nodes[k]) += f;
      out.col(partner[k]) += f;
    } else {
      out.col(nodes[k]) += interface_forces.col(col);
    }
  }
}

void SolidInterface::motion(const SolverState& state, Eigen::Matrix3Xd& positions_out,
                            Eigen::Matrix3Xd& velocities_out) const {
  const auto n = static_cast<Eigen::Index>(nodes.size());
  positions_out.resize(3, n);
  velocities_out.resize(3, n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto node = nodes[static_cast<std::size_t>(k)];
    if (mid_surface_pairs) {
      const auto other = partner[static_cast<std::size_t>(k)];
      positions_out.col(k) = 0.5 * (state.position.col(node) + state.position.col(other));
      velocities_out.col(k) = 0.5 * (state.velocity.col(node) + state.velocity.col(other));
    } else {
      positions_out.col(k) = state.position.col(node);
      velocities_out.col(k) = state.velocity.col(node);
    }
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

SolidInterface brick_mid_surface_interface(const Mesh& mesh, const std::string& source) {
  SolidInterface s;
  s.dimension = 3;
  s.nodes_per_cell = 3;
  s.mid_surface_pairs = true;
  const auto num_nodes = static_cast<std::size_t>(mesh.num_nodes());
  std::vector<std::int64_t> top_of(num_nodes, -1), index_of(num_nodes, -1);
  std::vector<std::uint8_t> on_top(num_nodes, 0);
  for (const auto& h : mesh.hexahedra) {
    for (int a = 4; a < 8; ++a) on_top[static_cast<std::size_t>(h[a])] = 1;
  }
  for (std::size_t e = 0; e < mesh.hexahedra.size(); ++e) {
    const auto& h = mesh.hexahedra[e];
    for (int a = 0; a < 4; ++a) {
      const auto bottom = static_cast<std::size_t>(h[a]);
      if (on_top[bottom] || (top_of[bottom] >= 0 && top_of[bottom] != h[a + 4])) {
        throw std::invalid_argument(fmt::format(
            "{}: /mesh/hexahedra[{}]: node {} is {}; the coupled mid-surface needs leaflets one brick thick "
            "(nodes 0-3 on the ventricular face, 4-7 above them on the aortic face)", source, e, h[a],
            on_top[bottom] ? "on both faces" : fmt::format("paired with nodes {} and {}", top_of[bottom], h[a + 4])));
      }
      if (top_of[bottom] < 0) {
        top_of[bottom] = h[a + 4];
        index_of[bottom] = static_cast<std::int64_t>(s.nodes.size());
        s.nodes.push_back(h[a]);
        s.partner.push_back(h[a + 4]);
      }
    }
  }
  const auto n = static_cast<Eigen::Index>(s.nodes.size());
  s.positions.resize(3, n);
  s.node_thickness.resize(n);
  s.node_areas = Eigen::VectorXd::Zero(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const Eigen::Vector3d b = mesh.nodes.col(s.nodes[static_cast<std::size_t>(k)]);
    const Eigen::Vector3d t = mesh.nodes.col(s.partner[static_cast<std::size_t>(k)]);
    s.positions.col(k) = 0.5 * (b + t);
    s.node_thickness(k) = (t - b).norm();
  }
  s.cells.resize(3, 2 * static_cast<Eigen::Index>(mesh.hexahedra.size()));
  Eigen::Index cell = 0;
  for (const auto& h : mesh.hexahedra) {
    std::array<int, 4> q{};
    for (int a = 0; a < 4; ++a) q[static_cast<std::size_t>(a)] = static_cast<int>(index_of[static_cast<std::size_t>(h[a])]);
    // 0-1-2-3 runs counter-clockwise seen from the outflow side: the triangles' normals point there.
    for (const auto& tri : {std::array<int, 3>{q[0], q[1], q[2]}, std::array<int, 3>{q[0], q[2], q[3]}}) {
      const double area = 0.5 * (s.positions.col(tri[1]) - s.positions.col(tri[0]))
                                    .cross(s.positions.col(tri[2]) - s.positions.col(tri[0]))
                                    .norm();
      for (int a = 0; a < 3; ++a) {
        s.cells(a, cell) = tri[static_cast<std::size_t>(a)];
        s.node_areas(tri[static_cast<std::size_t>(a)]) += area / 3.0;
      }
      ++cell;
    }
  }
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
