#include "valvefsi/solid/leaflet_contact.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Geometry>
#include <nanoflann.hpp>

namespace valvefsi::solid {

Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                          Eigen::Vector3d& weights) {
  // Inside the prism over the triangle: the projection onto its plane.
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  const Eigen::Vector3d q = p - (p - a).dot(n) / n2 * n;
  const double wa = (b - q).cross(c - q).dot(n) / n2;
  const double wb = (c - q).cross(a - q).dot(n) / n2;
  const double wc = 1.0 - wa - wb;
  if (wa >= 0 && wb >= 0 && wc >= 0) {
    weights = {wa, wb, wc};
    return q;
  }
  // Otherwise the nearest point of the three edges.
  const std::array<Eigen::Vector3d, 3> v{a, b, c};
  double best = HUGE_VAL;
  Eigen::Vector3d best_point = a;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d& s = v[i];
    const Eigen::Vector3d& e = v[(i + 1) % 3];
    const double u = std::clamp((p - s).dot(e - s) / (e - s).squaredNorm(), 0.0, 1.0);
    const Eigen::Vector3d point = s + u * (e - s);
    const double d = (p - point).squaredNorm();
    if (d < best) {
      best = d;
      best_point = point;
      weights.setZero();
      weights(i) = 1.0 - u;
      weights((i + 1) % 3) = u;
    }
  }
  return best_point;
}

LeafletContact::LeafletContact(const ShellModel& model, std::vector<int> surface_of_node, bool self_contact)
    : surface_of_node_(std::move(surface_of_node)), self_contact_(self_contact) {
  const Eigen::Index n = model.reference_positions.cols();
  half_thickness_ = Eigen::VectorXd::Zero(n);
  double max_thickness = 0.0, max_reach = 0.0;
  for (const auto& el : model.elements) {
    max_thickness = std::max(max_thickness, el.thickness);
    const Eigen::Vector3d centroid = (model.reference_positions.col(el.nodes[0]) + model.reference_positions.col(el.nodes[1]) +
                                      model.reference_positions.col(el.nodes[2])) / 3.0;
    for (const auto a : el.nodes) {
      half_thickness_(a) = std::max(half_thickness_(a), 0.5 * el.thickness);
      max_reach = std::max(max_reach, (model.reference_positions.col(a) - centroid).norm());
    }
  }
  margin_ = max_thickness;
  // Stretch allowance: tissue rarely exceeds 30 % strain before the material guard stops it.
  search_radius_ = 1.3 * max_reach + max_thickness + margin_;
}

void LeafletContact::rebuild(const ShellModel& model, const Eigen::Matrix3Xd& x,
                             ContactCandidates& candidates) const {
  const auto num_elements = static_cast<Eigen::Index>(model.elements.size());
  Eigen::Matrix3Xd centroids(3, num_elements);
  for (Eigen::Index e = 0; e < num_elements; ++e) {
    const auto& nodes = model.elements[static_cast<std::size_t>(e)].nodes;
    centroids.col(e) = (x.col(nodes[0]) + x.col(nodes[1]) + x.col(nodes[2])) / 3.0;
  }
  using Tree = nanoflann::KDTreeEigenMatrixAdaptor<Eigen::Matrix3Xd, 3, nanoflann::metric_L2_Simple, false>;
  const Tree tree(3, std::cref(centroids), 16);
  auto& pairs = candidates.pairs;
  pairs.clear();
  std::vector<std::pair<Eigen::Index, double>> matches;
  const nanoflann::SearchParams params(32, 0.0f, false);
  for (Eigen::Index i = 0; i < x.cols(); ++i) {
    if (model.fixed[static_cast<std::size_t>(i)]) continue;
    matches.clear();
    const Eigen::Vector3d p = x.col(i);
    tree.index->radiusSearch(p.data(), search_radius_ * search_radius_, matches, params);
    for (const auto& [e, d2] : matches) {
      const auto& nodes = model.elements[static_cast<std::size_t>(e)].nodes;
      if (nodes[0] == i || nodes[1] == i || nodes[2] == i) continue;
      if (!surface_of_node_.empty() &&
          surface_of_node_[static_cast<std::size_t>(nodes[0])] == surface_of_node_[static_cast<std::size_t>(i)]) {
        if (!self_contact_) continue;
        // Neighbours along the surface never touch (kSelfContactExclusion says why).
        const auto& x0 = model.reference_positions;
        const double reach = kSelfContactExclusion *
                             (half_thickness_(i) + 0.5 * model.elements[static_cast<std::size_t>(e)].thickness);
        Eigen::Vector3d w;
        const Eigen::Vector3d c =
            closest_point_on_triangle(x0.col(i), x0.col(nodes[0]), x0.col(nodes[1]), x0.col(nodes[2]), w);
        if ((x0.col(i) - c).norm() < reach) continue;
      }
      pairs.emplace_back(static_cast<std::int32_t>(i), static_cast<std::int32_t>(e));
    }
  }
  candidates.positions_at_build = x;
  ++candidates.rebuilds;
}

double LeafletContact::pair_mass(double m_node, const Eigen::Vector3d& w, const Eigen::Vector3d& triangle_masses) {
  return 1.0 / (1.0 / m_node + w.cwiseAbs2().cwiseQuotient(triangle_masses).sum());
}

namespace {
// The dashpot of node i against triangle `el` at weights w: 2 ratio sqrt(k m_pair).
double pair_damping(const ShellModel& model, std::int32_t i, const ShellElement& el, const Eigen::Vector3d& w,
                    double k, double damping_ratio) {
  const Eigen::Vector3d masses(model.nodal_mass(el.nodes[0]), model.nodal_mass(el.nodes[1]),
                               model.nodal_mass(el.nodes[2]));
  return 2.0 * damping_ratio * std::sqrt(k * LeafletContact::pair_mass(model.nodal_mass(i), w, masses));
}
}  // namespace

std::int64_t LeafletContact::add_forces(const ShellModel& model, const Eigen::Matrix3Xd& x,
                                        double stiffness_per_mass, Eigen::Matrix3Xd& forces,
                                        ContactCandidates& candidates, const Eigen::Matrix3Xd* velocity,
                                        double damping_ratio) const {
  if (candidates.positions_at_build.cols() != x.cols() ||
      (x - candidates.positions_at_build).colwise().norm().maxCoeff() > 0.5 * margin_) {
    rebuild(model, x, candidates);
  }
  const bool damped = velocity != nullptr && damping_ratio > 0.0;
  std::int64_t in_contact = 0;
  Eigen::Vector3d w, direction;
  for (const auto& [i, e] : candidates.pairs) {
    const double g = gap(model, x, i, e, direction, w);
    if (g >= 0.0) continue;
    const ShellElement& el = model.elements[static_cast<std::size_t>(e)];
    const double k = stiffness_per_mass * model.nodal_mass(i);
    double normal_force = -k * g;
    if (damped) {
      const double c = pair_damping(model, i, el, w, k, damping_ratio);
      const Eigen::Vector3d relative = velocity->col(i) - (w(0) * velocity->col(el.nodes[0]) +
                                                           w(1) * velocity->col(el.nodes[1]) +
                                                           w(2) * velocity->col(el.nodes[2]));
      normal_force = std::max(0.0, normal_force - c * relative.dot(direction));
    }
    const Eigen::Vector3d f = normal_force * direction;
    forces.col(i) += f;
    for (int a = 0; a < 3; ++a) forces.col(el.nodes[a]) -= w(a) * f;
    ++in_contact;
  }
  return in_contact;
}

double LeafletContact::gap(const ShellModel& model, const Eigen::Matrix3Xd& x, std::int32_t i, std::int32_t e,
                           Eigen::Vector3d& direction, Eigen::Vector3d& weights) const {
  const ShellElement& el = model.elements[static_cast<std::size_t>(e)];
  return pair_gap(x.col(i), x.col(el.nodes[0]), x.col(el.nodes[1]), x.col(el.nodes[2]), half_thickness_(i),
                  el.thickness, direction, weights);
}

double LeafletContact::pair_gap(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                const Eigen::Vector3d& c, double node_half_thickness, double triangle_thickness,
                                Eigen::Vector3d& direction, Eigen::Vector3d& weights) {
  const Eigen::Vector3d closest = closest_point_on_triangle(p, a, b, c, weights);
  const Eigen::Vector3d separation = p - closest;
  const double distance = separation.norm();
  const double g = distance - (node_half_thickness + 0.5 * triangle_thickness);
  if (g >= 0.0) return g;
  if (distance > 1e-9 * triangle_thickness) {
    direction = separation / distance;
  } else {  // on the mid-surface itself: push along the triangle's normal
    direction = (b - a).cross(c - a).normalized();
  }
  return g;
}

void LeafletContact::add_tangent(const ShellModel& model, const Eigen::Matrix3Xd& x, double stiffness_per_mass,
                                 const ContactCandidates& candidates, std::vector<NodeBlock>& blocks) const {
  // The pair's force on its four nodes: [f, -w_a f, -w_b f, -w_c f], f = -k g n.
  const auto pair_force = [](const Eigen::Matrix<double, 12, 1>& q, double half, double thickness, double k,
                             Eigen::Matrix<double, 12, 1>& force) {
    Eigen::Vector3d w, n;
    force.setZero();
    const double g = pair_gap(q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), q.segment<3>(9), half, thickness, n, w);
    if (g >= 0.0) return;
    const Eigen::Vector3d f = -k * g * n;
    force.segment<3>(0) = f;
    for (int a = 0; a < 3; ++a) force.segment<3>(3 + 3 * a) = -w(a) * f;
  };
  Eigen::Vector3d w, direction;
  Eigen::Matrix<double, 12, 1> q, fp, fm;
  Eigen::Matrix<double, 12, 12> stiffness;
  for (const auto& [i, e] : candidates.pairs) {
    if (gap(model, x, i, e, direction, w) >= 0.0) continue;
    const ShellElement& el = model.elements[static_cast<std::size_t>(e)];
    const std::array<std::int32_t, 4> nodes{i, el.nodes[0], el.nodes[1], el.nodes[2]};
    for (int a = 0; a < 4; ++a) q.segment<3>(3 * a) = x.col(nodes[static_cast<std::size_t>(a)]);
    const double half = half_thickness_(i);
    const double k = stiffness_per_mass * model.nodal_mass(i);
    // Central difference of the pair's exact force (as the element tangents reuse the element's
    // force): the gap's geometry (the closest point's motion, the normal's turn) comes with it.
    // Step 1e-6 of the contact distance: truncation ~1e-12, round-off ~1e-9 of k.
    const double h = 1e-6 * (half + 0.5 * el.thickness);
    for (int d = 0; d < 12; ++d) {
      const double saved = q(d);
      q(d) = saved + h;
      pair_force(q, half, el.thickness, k, fp);
      q(d) = saved - h;
      pair_force(q, half, el.thickness, k, fm);
      q(d) = saved;
      stiffness.col(d) = (fm - fp) / (2.0 * h);  // -d(force)/dx: a stiffness, as K_int
    }
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        blocks.push_back({nodes[static_cast<std::size_t>(a)], nodes[static_cast<std::size_t>(b)],
                          stiffness.block<3, 3>(3 * a, 3 * b)});
      }
    }
  }
}

void LeafletContact::add_damping_tangent(const ShellModel& model, const Eigen::Matrix3Xd& x, double stiffness_per_mass,
                                         double damping_ratio, double scale, const ContactCandidates& candidates,
                                         std::vector<NodeBlock>& blocks) const {
  if (!(damping_ratio > 0.0)) return;
  Eigen::Vector3d w, direction;
  for (const auto& [i, e] : candidates.pairs) {
    const double g = gap(model, x, i, e, direction, w);
    if (g >= 0.0) continue;
    const ShellElement& el = model.elements[static_cast<std::size_t>(e)];
    const double c = pair_damping(model, i, el, w, stiffness_per_mass * model.nodal_mass(i), damping_ratio);
    const std::array<std::int32_t, 4> nodes{i, el.nodes[0], el.nodes[1], el.nodes[2]};
    const std::array<double, 4> sign{1.0, -w(0), -w(1), -w(2)};
    const Eigen::Matrix3d nn = (scale * c) * (direction * direction.transpose());
    for (std::size_t a = 0; a < 4; ++a) {
      for (std::size_t b = 0; b < 4; ++b) blocks.push_back({nodes[a], nodes[b], (sign[a] * sign[b]) * nn});
    }
  }
}

double LeafletContact::penalty_energy(const ShellModel& model, const Eigen::Matrix3Xd& x, double stiffness_per_mass,
                                      const ContactCandidates& candidates) const {
  double energy = 0.0;
  Eigen::Vector3d w, direction;
  for (const auto& [i, e] : candidates.pairs) {
    const double g = gap(model, x, i, e, direction, w);
    if (g < 0.0) energy += 0.5 * stiffness_per_mass * model.nodal_mass(i) * g * g;
  }
  return energy;
}

}  // namespace valvefsi::solid
