#pragma once
// Fold angle of a triangle about one of its edges and its gradient (rotation-free bending).
// Triangle A = (x0, x1, x2) counter-clockwise about its normal nA, edge x0 -> x1, x2 opposite.
// Moving x2 along nA by d rotates A about the edge by d/hA (hA: height of x2 over the edge),
// so dphi/dx2 = nA/hA, dphi/dx0 = -(1-s) nA/hA, dphi/dx1 = -s nA/hA, with s the position
// of x2's foot along the edge (0 at x0, 1 at x1). Across an interior edge with neighbour
// B = (x1, x0, x3) the fold angle theta = phi_A + phi_B is positive when the surface bends
// towards its normal.
#include <array>
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace valvefsi::solid {

struct HingeSide {
  Eigen::Vector3d unit_normal;
  Eigen::Vector3d grad_opposite;  // d phi / d x_opposite
  Eigen::Vector3d grad_start;     // d phi / d x0
  Eigen::Vector3d grad_end;       // d phi / d x1
};

// One side of a hinge: triangle (x0, x1, x_opposite) with x0 -> x1 ordered so that the normal
// (x1 - x0) x (x_opposite - x0) is this side's outward normal; for side B pass the edge reversed
// back into A's direction via `reversed` (then B = (x1, x0, x3)).
inline HingeSide hinge_side(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                            const Eigen::Vector3d& opposite, bool reversed) {
  const Eigen::Vector3d e = x1 - x0;
  const double edge_length = e.norm();
  const Eigen::Vector3d e_hat = e / edge_length;
  const Eigen::Vector3d raw_normal =
      reversed ? Eigen::Vector3d((x0 - x1).cross(opposite - x1)) : Eigen::Vector3d(e.cross(opposite - x0));
  const double twice_area = raw_normal.norm();
  HingeSide side;
  side.unit_normal = raw_normal / twice_area;
  const double height = twice_area / edge_length;
  const double s = (opposite - x0).dot(e_hat) / edge_length;
  side.grad_opposite = side.unit_normal / height;
  side.grad_start = -(1.0 - s) * side.grad_opposite;
  side.grad_end = -s * side.grad_opposite;
  return side;
}

// Signed fold angle across edge x0 -> x1 between side A and side B.
inline double fold_angle(const HingeSide& a, const HingeSide& b, const Eigen::Vector3d& x0,
                         const Eigen::Vector3d& x1) {
  const Eigen::Vector3d e_hat = (x1 - x0).normalized();
  return std::atan2(b.unit_normal.cross(a.unit_normal).dot(e_hat), a.unit_normal.dot(b.unit_normal));
}

// Signed rotation of side A away from a fixed reference normal n0 (a clamped edge).
inline double clamped_angle(const HingeSide& a, const Eigen::Vector3d& n0, const Eigen::Vector3d& x0,
                            const Eigen::Vector3d& x1) {
  const Eigen::Vector3d e_hat = (x1 - x0).normalized();
  return std::atan2(n0.cross(a.unit_normal).dot(e_hat), n0.dot(a.unit_normal));
}

}  // namespace valvefsi::solid
