#pragma once
// Closest point of a triangle or segment to a query point, as barycentric weights of the cell's
// nodes (non-negative, summing to one: the point is clamped to the cell).

#include <Eigen/Core>

#include <array>

namespace valvefsi::coupling::detail {

struct ClosestPoint {
  std::array<double, 3> weights{};  // of the cell's nodes, in cell order (third unused for segments)
  double distance_squared = 0.0;
};

ClosestPoint closest_point_on_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b);
ClosestPoint closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                       const Eigen::Vector3d& c);

}  // namespace valvefsi::coupling::detail
