#include "closest_point.hpp"

#include <algorithm>
#include <limits>

namespace valvefsi::coupling::detail {

ClosestPoint closest_point_on_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d edge = b - a;
  const double length_squared = edge.squaredNorm();
  // A collapsed segment is its first node.
  const double t = length_squared > 0.0 ? std::clamp((p - a).dot(edge) / length_squared, 0.0, 1.0) : 0.0;
  ClosestPoint result;
  result.weights = {1.0 - t, t, 0.0};
  result.distance_squared = (a + t * edge - p).squaredNorm();
  return result;
}

ClosestPoint closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                       const Eigen::Vector3d& c) {
  // Project onto the triangle's plane; inside, the barycentric coordinates are the weights.
  const Eigen::Vector3d e0 = b - a;
  const Eigen::Vector3d e1 = c - a;
  const Eigen::Vector3d d = p - a;
  const double g00 = e0.dot(e0);
  const double g01 = e0.dot(e1);
  const double g11 = e1.dot(e1);
  const double determinant = g00 * g11 - g01 * g01;
  if (determinant > 1e-14 * g00 * g11) {
    const double d0 = d.dot(e0);
    const double d1 = d.dot(e1);
    const double wb = (g11 * d0 - g01 * d1) / determinant;
    const double wc = (g00 * d1 - g01 * d0) / determinant;
    const double wa = 1.0 - wb - wc;
    if (wa >= 0.0 && wb >= 0.0 && wc >= 0.0) {
      ClosestPoint result;
      result.weights = {wa, wb, wc};
      result.distance_squared = (wa * a + wb * b + wc * c - p).squaredNorm();
      return result;
    }
  }
  // Outside (or a degenerate triangle): the closest point of a convex cell lies on its boundary.
  const ClosestPoint ab = closest_point_on_segment(p, a, b);
  const ClosestPoint bc = closest_point_on_segment(p, b, c);
  const ClosestPoint ca = closest_point_on_segment(p, c, a);
  ClosestPoint result;
  if (ab.distance_squared <= bc.distance_squared && ab.distance_squared <= ca.distance_squared) {
    result.weights = {ab.weights[0], ab.weights[1], 0.0};
    result.distance_squared = ab.distance_squared;
  } else if (bc.distance_squared <= ca.distance_squared) {
    result.weights = {0.0, bc.weights[0], bc.weights[1]};
    result.distance_squared = bc.distance_squared;
  } else {
    result.weights = {ca.weights[1], 0.0, ca.weights[0]};
    result.distance_squared = ca.distance_squared;
  }
  return result;
}

}  // namespace valvefsi::coupling::detail
