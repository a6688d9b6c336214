#include "valvefsi/coupling/interface_mapping.hpp"

#include "radial_basis_system.hpp"
#include "sparse_mappings.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace valvefsi::coupling {

namespace {

[[noreturn]] void bad_input(const std::string& field, const std::string& seen, const std::string& allowed) {
  throw std::invalid_argument("interface mapping: " + field + " is " + seen + "; allowed: " + allowed);
}

std::string shape(Eigen::Index rows, Eigen::Index cols) {
  return std::to_string(rows) + " x " + std::to_string(cols);
}

void check_finite(const Eigen::Matrix3Xd& x, const std::string& field) {
  for (Eigen::Index j = 0; j < x.cols(); ++j) {
    for (Eigen::Index d = 0; d < 3; ++d) {
      if (!std::isfinite(x(d, j))) {
        std::ostringstream seen;
        seen << x(d, j) << " at column " << j << ", row " << d;
        bad_input(field, seen.str(), "finite numbers");
      }
    }
  }
}

void check_surface(const InterfaceMesh& surface, MappingMethod method) {
  const Eigen::Index nodes = surface.positions.cols();
  if (nodes == 0) bad_input("solid_surface.positions", "empty (0 nodes)", "at least one node");
  check_finite(surface.positions, "solid_surface.positions");
  if (surface.nodes_per_cell != 2 && surface.nodes_per_cell != 3) {
    bad_input("solid_surface.nodes_per_cell", std::to_string(surface.nodes_per_cell),
              "3 (triangles in 3D) or 2 (segments in 2D)");
  }
  if (surface.cells.cols() > 0 && surface.cells.rows() != surface.nodes_per_cell) {
    bad_input("solid_surface.cells", "a " + shape(surface.cells.rows(), surface.cells.cols()) + " matrix",
              std::to_string(surface.nodes_per_cell) + " rows (nodes_per_cell) x n_cells");
  }
  for (Eigen::Index c = 0; c < surface.cells.cols(); ++c) {
    for (Eigen::Index k = 0; k < surface.cells.rows(); ++k) {
      const int node = surface.cells(k, c);
      if (node < 0 || node >= nodes) {
        bad_input("solid_surface.cells(" + std::to_string(k) + ", " + std::to_string(c) + ")", std::to_string(node),
                  "a node index in [0, " + std::to_string(nodes - 1) + "]");
      }
    }
  }
  if (surface.node_areas.size() != 0 && surface.node_areas.size() != nodes) {
    bad_input("solid_surface.node_areas", std::to_string(surface.node_areas.size()) + " entries",
              "one per node (" + std::to_string(nodes) + ") or none");
  }
  if (method == MappingMethod::nearest_projection && surface.cells.cols() == 0) {
    bad_input("solid_surface.cells", "empty", "at least one cell for nearest-projection");
  }
}

}  // namespace

InterfaceMapping::InterfaceMapping(Eigen::SparseMatrix<double, Eigen::RowMajor> h,
                                   std::shared_ptr<const detail::RadialBasisSystem> radial_basis)
    : h_(std::move(h)), radial_basis_(std::move(radial_basis)) {}

InterfaceMapping InterfaceMapping::build(const InterfaceMesh& solid_surface, const Eigen::Matrix3Xd& fluid_points,
                                         const MappingOptions& options) {
  check_surface(solid_surface, options.method);
  if (fluid_points.cols() == 0) bad_input("fluid_points", "empty (0 points)", "at least one point");
  check_finite(fluid_points, "fluid_points");
  switch (options.method) {
    case MappingMethod::nearest_neighbor:
      return InterfaceMapping(detail::nearest_neighbor_matrix(solid_surface, fluid_points), nullptr);
    case MappingMethod::nearest_projection:
      return InterfaceMapping(detail::nearest_projection_matrix(solid_surface, fluid_points), nullptr);
    case MappingMethod::radial_basis:
      if (!(std::isfinite(options.rbf_support_radius) && options.rbf_support_radius > 0.0)) {
        bad_input("rbf_support_radius", std::to_string(options.rbf_support_radius) + " m",
                  "a finite radius > 0 m (a few node spacings) for the rbf mapping");
      }
      if (options.rbf_nodes_per_cluster < 0) {
        bad_input("rbf_nodes_per_cluster", std::to_string(options.rbf_nodes_per_cluster),
                  "0 (one global system) or a cluster size > 0 (partition of unity; 30-100 is typical)");
      }
      if (options.rbf_nodes_per_cluster > 0) {
        return InterfaceMapping(detail::partition_of_unity_rbf_matrix(solid_surface.positions, fluid_points,
                                                                      options.rbf_support_radius,
                                                                      options.rbf_linear_polynomial,
                                                                      options.rbf_nodes_per_cluster),
                                nullptr);
      }
      return InterfaceMapping({}, std::make_shared<const detail::RadialBasisSystem>(
                                      solid_surface.positions, fluid_points, options.rbf_support_radius,
                                      options.rbf_linear_polynomial));
  }
  bad_input("method", std::to_string(static_cast<int>(options.method)),
            "nearest_neighbor, nearest_projection, radial_basis");
}

Eigen::Matrix3Xd InterfaceMapping::map_consistent(const Eigen::Matrix3Xd& values_at_nodes) const {
  if (values_at_nodes.cols() != node_count()) {
    bad_input("map_consistent: values_at_nodes", shape(3, values_at_nodes.cols()),
              shape(3, node_count()) + " (one column per solid node)");
  }
  if (radial_basis_) return radial_basis_->consistent(values_at_nodes.transpose()).transpose();
  return (h_ * values_at_nodes.transpose()).transpose();
}

Eigen::Matrix3Xd InterfaceMapping::map_conservative(const Eigen::Matrix3Xd& forces_at_points) const {
  if (forces_at_points.cols() != point_count()) {
    bad_input("map_conservative: forces_at_points", shape(3, forces_at_points.cols()),
              shape(3, point_count()) + " (one column per fluid point)");
  }
  if (radial_basis_) return radial_basis_->conservative(forces_at_points.transpose()).transpose();
  return (h_.transpose() * forces_at_points.transpose()).transpose();
}

const Eigen::SparseMatrix<double, Eigen::RowMajor>& InterfaceMapping::matrix() const {
  return radial_basis_ ? radial_basis_->assembled_matrix() : h_;
}

Eigen::Index InterfaceMapping::point_count() const {
  return radial_basis_ ? radial_basis_->point_count() : h_.rows();
}

Eigen::Index InterfaceMapping::node_count() const {
  return radial_basis_ ? radial_basis_->node_count() : h_.cols();
}

MappingMethod parse_mapping_method(std::string_view name) {
  if (name == "nearest-neighbor") return MappingMethod::nearest_neighbor;
  if (name == "nearest-projection") return MappingMethod::nearest_projection;
  if (name == "rbf") return MappingMethod::radial_basis;
  throw std::invalid_argument("unknown mapping method '" + std::string(name) +
                              "'; allowed: \"nearest-neighbor\", \"nearest-projection\", \"rbf\"");
}

}  // namespace valvefsi::coupling
