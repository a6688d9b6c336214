#pragma once
// Precomputed reference data of the rotation-free thin-shell triangle (docs/solid_fe.md):
// constant-strain membrane plus a constant curvature per triangle recovered from the fold
// angles across its three edges, both integrated through the thickness with Gauss points.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "valvefsi/solid/mesh.hpp"

namespace valvefsi::solid {

enum class EdgeKind : std::uint8_t {
  interior,  // shared with a neighbour triangle: fold angle between the two
  free,      // boundary edge with no support: zero normal curvature across it
  clamped,   // both end nodes fixed: rotation measured against the reference normal
  mirror,    // on a symmetry plane: fold angle against the element's mirror image
};

struct ShellElement {
  std::array<std::int32_t, 3> nodes{};
  // Neighbour's node opposite edge i (edge i joins nodes[(i+1)%3] -> nodes[(i+2)%3]); -1 if none.
  std::array<std::int32_t, 3> opposite{-1, -1, -1};
  // Interior edge i: the neighbour triangle and its slot for the same edge (its own hinge side
  // there is this element's neighbour side, start and end swapped); -1 if none.
  std::array<std::int32_t, 3> neighbour{-1, -1, -1};
  std::array<std::int8_t, 3> neighbour_slot{-1, -1, -1};
  std::array<EdgeKind, 3> edge_kind{EdgeKind::free, EdgeKind::free, EdgeKind::free};
  std::array<double, 3> reference_fold_angle{};  // theta0 of interior and mirror edges
  std::array<std::int8_t, 3> mirror_plane{-1, -1, -1};  // index into ShellModel::mirror_planes
  Eigen::Matrix<double, 3, 2> shape_gradients;    // dN_a/dX in the material frame (rows = nodes)
  Eigen::Matrix3d curvature_from_angles;          // kappa_voigt = this * (theta - theta0)
  Eigen::Vector3d reference_normal;
  Eigen::Vector3d circumferential;  // material frame in the reference configuration
  Eigen::Vector3d radial;
  double area = 0;            // reference area (m^2)
  double thickness = 0;       // reference thickness (m)
  double min_height = 0;      // smallest reference altitude, the length for the stable step (m)
};

struct ShellModelOptions {
  double density = 1100.0;                 // kg/m^3
  int thickness_points = 3;                // Gauss-Legendre points through the thickness (2..5)
  bool clamp_fixed_edges = true;           // edges with both nodes fixed resist rotation
  std::vector<std::int64_t> fixed_nodes;   // nodes held in place
  std::vector<Plane> symmetry_planes;      // boundary edges lying on one bend as if mirrored
};

struct ShellModel {
  std::vector<ShellElement> elements;
  Eigen::Matrix3Xd reference_positions;
  Eigen::VectorXd nodal_mass;     // lumped mass (kg)
  std::vector<std::uint8_t> fixed;  // 1 for fixed nodes
  std::vector<Plane> mirror_planes;  // symmetry planes (unit normals)
  int thickness_points = 3;
  double density = 1100.0;
  std::array<double, 5> gauss_points{};   // through-thickness coordinates in [-1, 1]
  std::array<double, 5> gauss_weights{};  // weights summing to 2
};

// Builds the element data from a mesh; throws std::invalid_argument naming `source` for
// non-manifold edges, inconsistent orientation or degenerate triangles.
ShellModel build_shell_model(const Mesh& mesh, const ShellModelOptions& options,
                             const std::string& source = "mesh");

}  // namespace valvefsi::solid
