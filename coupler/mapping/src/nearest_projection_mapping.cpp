#include "closest_point.hpp"
#include "point_cloud_tree.hpp"
#include "sparse_mappings.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace valvefsi::coupling::detail {

namespace {

ClosestPoint closest_point_on_cell(const InterfaceMesh& surface, Eigen::Index cell, const Eigen::Vector3d& p) {
  const auto node = [&](int corner) -> Eigen::Vector3d { return surface.positions.col(surface.cells(corner, cell)); };
  if (surface.nodes_per_cell == 2) return closest_point_on_segment(p, node(0), node(1));
  return closest_point_on_triangle(p, node(0), node(1), node(2));
}

}  // namespace

Eigen::SparseMatrix<double, Eigen::RowMajor> nearest_projection_matrix(const InterfaceMesh& surface,
                                                                        const Eigen::Matrix3Xd& points) {
  const Eigen::Index cell_count = surface.cells.cols();
  const int corners = surface.nodes_per_cell;
  Eigen::Matrix3Xd centroids(3, cell_count);
  Eigen::VectorXd cell_radius(cell_count);  // largest centroid-to-node distance of each cell
  for (Eigen::Index c = 0; c < cell_count; ++c) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int k = 0; k < corners; ++k) sum += surface.positions.col(surface.cells(k, c));
    centroids.col(c) = sum / corners;
    double radius = 0.0;
    for (int k = 0; k < corners; ++k) {
      radius = std::max(radius, (surface.positions.col(surface.cells(k, c)) - centroids.col(c)).norm());
    }
    cell_radius(c) = radius;
  }
  const double largest_cell_radius = cell_radius.maxCoeff();
  const PointCloudTree centroid_tree(centroids);

  // Exact candidate set: the nearest centroid d0 bounds the distance to the surface from
  // above (the centroid lies in its cell), and a cell whose centroid is farther than
  // d0 + its radius cannot be closer. So points off the surface are handled exactly too.
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(points.cols() * corners));
  std::vector<std::pair<std::uint32_t, double>> candidates;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3d p = points.col(i);
    const auto [nearest_cell, d0_squared] = centroid_tree.nearest(p);
    Eigen::Index best_cell = nearest_cell;
    ClosestPoint best = closest_point_on_cell(surface, best_cell, p);
    centroid_tree.within(p, (std::sqrt(d0_squared) + largest_cell_radius) * (1.0 + 1e-12) + 1e-300, candidates);
    for (const auto& [cell, centroid_distance_squared] : candidates) {
      const double lower_bound = std::sqrt(centroid_distance_squared) - cell_radius(cell);
      if (lower_bound > 0.0 && lower_bound * lower_bound > best.distance_squared) continue;
      const ClosestPoint candidate = closest_point_on_cell(surface, cell, p);
      // Ties (a point over a shared edge) go to the lower cell index, so the result is deterministic.
      if (candidate.distance_squared < best.distance_squared ||
          (candidate.distance_squared == best.distance_squared && static_cast<Eigen::Index>(cell) < best_cell)) {
        best = candidate;
        best_cell = cell;
      }
    }
    for (int k = 0; k < corners; ++k) {
      if (best.weights[static_cast<std::size_t>(k)] != 0.0) {
        entries.emplace_back(i, surface.cells(k, best_cell), best.weights[static_cast<std::size_t>(k)]);
      }
    }
  }
  Eigen::SparseMatrix<double, Eigen::RowMajor> h(points.cols(), surface.positions.cols());
  h.setFromTriplets(entries.begin(), entries.end());  // repeated nodes in a cell are summed
  return h;
}

}  // namespace valvefsi::coupling::detail
