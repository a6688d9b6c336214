#pragma once
// The solid's side of a coupled run (docs/solid_fe.md, "Participant mode"): which mesh nodes the
// fluid sees, as triangles (3D) or segments (2D strip), their tributary areas and thickness, and
// how the fluid's forces become nodal forces and the nodes' state becomes interface motion.
// A one-brick-thick leaflet shows the fluid its mid-surface: each interface node is a pair of
// brick nodes (ventricular face, aortic face) moving as their mean, and each force is split half
// and half on the pair, so force and power are the same on both sides.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "valvefsi/solid/mesh.hpp"
#include "valvefsi/solid/explicit_solver.hpp"

namespace valvefsi::solid {

struct SolidInterface {
  int dimension = 3;
  std::vector<std::int64_t> nodes;    // mesh node of each interface node
  std::vector<std::int64_t> partner;  // 2D: the strip_back node tied to each; bricks: the aortic-face node
  bool mid_surface_pairs = false;     // bricks: motion = mean of node and partner, force half on each
  int nodes_per_cell = 3;             // 3: triangles, 2: segments
  Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic> cells;  // interface-node indices, one cell a column
  Eigen::Matrix3Xd positions;         // reference positions (z = 0 in 2D)
  Eigen::VectorXd node_areas;         // tributary area (m^2), or length in 2D (m)
  Eigen::VectorXd node_thickness;     // mean thickness of the adjacent triangles (m)
  double depth = 1.0;                 // 2D: strip depth (m) that turns N/m into N

  // Nodal forces (3 x mesh nodes, N) from forces at the interface nodes (N; N/m in 2D, applied
  // times the depth, half to each node of the front/back pair; bricks: half to each node of the
  // pair). `out` is resized once.
  void nodal_forces(const Eigen::Matrix3Xd& interface_forces, std::int64_t mesh_nodes, Eigen::Matrix3Xd& out) const;
  // Positions and velocities of the interface nodes in the solver's current state.
  void motion(const SolverState& state, Eigen::Matrix3Xd& positions_out, Eigen::Matrix3Xd& velocities_out) const;
};

// 3D: every mesh node and every triangle; node area = sum of the adjacent triangles' area / 3.
SolidInterface surface_interface(const Mesh& mesh);

// One-brick-thick leaflets (3D): the mid-surface of the bricks. Interface node k pairs the
// ventricular-face node hexahedra[e][a] with the aortic-face node hexahedra[e][a + 4] (a = 0..3);
// cells are each brick's mid-quadrilateral split into two triangles (normal to the outflow side);
// thickness per node = the pair's reference distance. Throws std::invalid_argument naming
// `source` when the bricks are not one layer thick (a node paired twice differently, or a node on
// both faces).
SolidInterface brick_mid_surface_interface(const Mesh& mesh, const std::string& source);

// 2D strip: the front nodes, segments between consecutive front nodes that share a triangle
// edge (attached end to free end, leaflet after leaflet), tributary lengths. Throws
// std::invalid_argument naming `source` when a tie's front node is not on z = 0.
SolidInterface strip_interface(const Mesh& mesh, const std::vector<StripTie>& ties, double depth,
                               const std::string& source);

}  // namespace valvefsi::solid
