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

#include "valvefsi/solid/element_model.hpp"
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

// Self-contact skips a node-triangle pair of the same surface when, in the reference
// configuration, the triangle lies within this many contact distances (t_node/2 + t_triangle/2)
// of the node. Why pi/2: the tightest fold a shell of thickness t can make without its inner face
// crossing itself has a mid-surface radius t/2, and points facing each other across it are a
// half-turn, pi t/2, apart along the surface; any two mid-surface points closer than that along
// a surface curved no tighter than t/2 are more than t apart in space (chord 2 rho sin(s/2 rho)
// >= t for s >= pi t/2, rho >= t/2), so a flat or curved leaflet feels no self-contact, while a
// fold brings pairs beyond this radius within t. A kink of a coarse mesh (curvature lumped at one
// edge) turns by up to 2 acos(2/pi) = 101 degrees before a pair at this radius touches.
inline constexpr double kSelfContactExclusion = 1.5707963267948966;

class LeafletContact {
 public:
  // surface_of_node: an id per node (e.g. its leaflet); pairs on the same surface are skipped
  // unless self_contact, which keeps those farther apart than kSelfContactExclusion contact
  // distances in the reference configuration. Empty: any triangle not touching the node may
  // contact it.
  LeafletContact(const ShellModel& model, std::vector<int> surface_of_node, bool self_contact = false);
  bool self_contact() const { return self_contact_; }

  // Adds the penalty forces k * penetration (k = stiffness_per_mass * nodal mass of the pair's
  // node) to `forces`, rebuilding `candidates` when some node moved more than half the margin;
  // returns the number of node-triangle pairs in contact. With a `velocity` (3 x nodes) and
  // damping_ratio > 0 each pair in contact also gets a normal dashpot c = 2 damping_ratio
  // sqrt(k m_pair) on the closing speed of the node and the triangle's closest point (m_pair:
  // the pair's reduced mass, pair_mass), the pair's normal force kept >= 0 (no adhesion):
  // docs/solid_fe.md, "Sixteenth session".
  std::int64_t add_forces(const ShellModel& model, const Eigen::Matrix3Xd& x, double stiffness_per_mass,
                          Eigen::Matrix3Xd& forces, ContactCandidates& candidates,
                          const Eigen::Matrix3Xd* velocity = nullptr, double damping_ratio = 0.0) const;
  // Reduced mass of a node of mass m_node against the point of a triangle with barycentric
  // weights w (lumped masses m_a): 1 / (1/m_node + sum w_a^2 / m_a), the mass a normal force
  // between them accelerates apart.
  static double pair_mass(double m_node, const Eigen::Vector3d& w, const Eigen::Vector3d& triangle_masses);
  // Energy stored in the penalties at x over the current candidates: sum of k g^2 / 2 (J), the
  // potential whose gradient add_forces applies (for the ledger's check).
  double penalty_energy(const ShellModel& model, const Eigen::Matrix3Xd& x, double stiffness_per_mass,
                        const ContactCandidates& candidates) const;
  // Tangent of the penalty forces at x over the current candidates, -d(force)/dx (a stiffness,
  // as ElementModel's internal-force tangent): per pair in contact the 4 x 4 blocks coupling the
  // node and the triangle's three nodes, with the gap's geometry (closest point, normal).
  void add_tangent(const ShellModel& model, const Eigen::Matrix3Xd& x, double stiffness_per_mass,
                   const ContactCandidates& candidates, std::vector<NodeBlock>& blocks) const;
  // The dashpots' damping matrix -d(force)/d(velocity) at x (damping_ratio > 0): per pair in
  // contact c (1, -w)(1, -w)^T (x) n n^T over the node and the triangle's three nodes, each block
  // times `scale` (the implicit scheme's d(velocity)/d(position)). The normal's and weights' turn
  // under the dashpot force is left out (an approximate tangent: the dashpot force is small).
  void add_damping_tangent(const ShellModel& model, const Eigen::Matrix3Xd& x, double stiffness_per_mass,
                           double damping_ratio, double scale, const ContactCandidates& candidates,
                           std::vector<NodeBlock>& blocks) const;

 private:
  void rebuild(const ShellModel& model, const Eigen::Matrix3Xd& x, ContactCandidates& candidates) const;

  // Penetration (negative gap) of node i into triangle e at x, its direction and the closest
  // point's barycentric weights; returns the gap (>= 0: apart).
  double gap(const ShellModel& model, const Eigen::Matrix3Xd& x, std::int32_t i, std::int32_t e,
             Eigen::Vector3d& direction, Eigen::Vector3d& weights) const;
  // The same for a node at p and a triangle (a, b, c).
  static double pair_gap(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c, double node_half_thickness, double triangle_thickness,
                         Eigen::Vector3d& direction, Eigen::Vector3d& weights);

  std::vector<int> surface_of_node_;
  bool self_contact_ = false;
  Eigen::VectorXd half_thickness_;            // per node
  double margin_ = 0;
  double search_radius_ = 0;                  // largest centroid-to-vertex distance + contact gap
};

}  // namespace valvefsi::solid
