#pragma once
// Mapping of data between the solid's interface surface (nodes) and the fluid's interface
// point cloud: consistent for motion (u_points = H u_nodes), conservative for loads
// (f_nodes = H^T f_points). See docs/coupling-numerics.md.

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <string_view>

namespace valvefsi::coupling {

namespace detail {
class RadialBasisSystem;
}

// The solid's interface surface: node positions (3 x n_nodes, m), cells (nodes_per_cell x n_cells,
// 0-based; 3 = triangles in 3D, 2 = segments in 2D, z = 0), node areas (m^2; m in 2D).
struct InterfaceMesh {
  Eigen::Matrix3Xd positions;
  int nodes_per_cell = 3;
  Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic> cells;
  Eigen::VectorXd node_areas;
};

enum class MappingMethod { nearest_neighbor, nearest_projection, radial_basis };

struct MappingOptions {
  MappingMethod method = MappingMethod::nearest_projection;
  double rbf_support_radius = 0.0;   // m; compact-support Wendland C2 RBF; required for radial_basis
  bool rbf_linear_polynomial = true; // augment with 1, x, y, z so that linear fields are exact
                                     // (false: the constant only, so rows still sum to one)
  int rbf_nodes_per_cluster = 0;     // 0: one global RBF system (exact interpolant; build grows ~n^2);
                                     // > 0: partition of unity of local RBF systems of about this
                                     // many nodes (sparse H, build ~linear: for large interfaces)
};

// A sparse matrix H (n_points x n_nodes) with rows summing to one, built once from the
// reference configuration. Consistent (motion): u_points = H u_nodes. Conservative (loads):
// f_nodes = H^T f_points, which preserves the total force (rows sum to 1) and the power
// (f_nodes . v_nodes = f_points . (H v_nodes)).
// For radial_basis, H = E A^-1 is dense in general: the mapping then applies it through a
// sparse factorisation, and matrix() assembles H only when asked (small interfaces, tests).
class InterfaceMapping {
 public:
  static InterfaceMapping build(const InterfaceMesh& solid_surface,
                                const Eigen::Matrix3Xd& fluid_points,
                                const MappingOptions& options);
  Eigen::Matrix3Xd map_consistent(const Eigen::Matrix3Xd& values_at_nodes) const;   // 3 x n_points
  Eigen::Matrix3Xd map_conservative(const Eigen::Matrix3Xd& forces_at_points) const; // 3 x n_nodes
  const Eigen::SparseMatrix<double, Eigen::RowMajor>& matrix() const;
  Eigen::Index point_count() const;
  Eigen::Index node_count() const;

 private:
  InterfaceMapping(Eigen::SparseMatrix<double, Eigen::RowMajor> h,
                   std::shared_ptr<const detail::RadialBasisSystem> radial_basis);
  Eigen::SparseMatrix<double, Eigen::RowMajor> h_;  // empty for radial_basis (its system holds H)
  std::shared_ptr<const detail::RadialBasisSystem> radial_basis_;
};

// "nearest-neighbor" | "nearest-projection" | "rbf"; throws std::invalid_argument naming the allowed values
MappingMethod parse_mapping_method(std::string_view name);

}  // namespace valvefsi::coupling
