#pragma once
// Leaflet-leaflet penalty contact: a node and a triangle of another surface (leaflet) may not
// come closer than the sum of their half thicknesses (mid-surfaces offset by t/2). Candidate
// node-triangle pairs come from a k-d tree of triangle centroids with a margin, rebuilt only
// when some node has moved more than half the margin since the last build. The candidate list is
// part of the solver's state (ContactCandidates): the order of the pairs sets the order of the
// force sums, so a restarted run continues bit for bit only with the same list.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "valvefsi/solid/shell_model.hpp"

namespace valvefsi::solid {

// Closest point to p on triangle (a, b, c); `weights` receives its barycentric coordinates.
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                          Eigen::Vector3d& weights);

// Node-triangle pairs that may touch, and the positions they were found at.
struct ContactCandidates {
  std::vector<std::pair<std::int32_t, std::int32_t>> pairs;  // (node, element)
  Eigen::Matrix3Xd positions_at_build;
  std::int64_t rebuilds = 0;
};

class LeafletContact {
 public:
  // surface_of_node: an id per node (e.g. its leaflet); pairs on the same surface are skipped.
  // Empty: any triangle not touching the node may contact it.
  LeafletContact(const ShellModel& model, std::vector<int> surface_of_node);

  // Adds the penalty forces k * penetration (k = stiffness_per_mass * nodal mass) to `forces`,
  // rebuilding `candidates` when some node moved more than half the margin; returns the number
  // of node-triangle pairs in contact.
  std::int64_t add_forces(const ShellModel& model, const Eigen::Matrix3Xd& x, double stiffness_per_mass,
                          Eigen::Matrix3Xd& forces, ContactCandidates& candidates) const;

 private:
  void rebuild(const ShellModel& model, const Eigen::Matrix3Xd& x, ContactCandidates& candidates) const;

  std::vector<int> surface_of_node_;
  Eigen::VectorXd half_thickness_;            // per node
  double margin_ = 0;
  double search_radius_ = 0;                  // largest centroid-to-vertex distance + contact gap
};

}  // namespace valvefsi::solid
