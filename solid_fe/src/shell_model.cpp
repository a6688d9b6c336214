#include "valvefsi/solid/shell_model.hpp"

#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <fmt/format.h>

#include "valvefsi/solid/hinge_angle.hpp"

namespace valvefsi::solid {
namespace {

void set_gauss_rule(int n, ShellModel& model, const std::string& source) {
  // Gauss-Legendre abscissae and weights on [-1, 1].
  static const std::array<std::array<double, 5>, 5> points{{
      {0.0},
      {-0.5773502691896258, 0.5773502691896258},
      {-0.7745966692414834, 0.0, 0.7745966692414834},
      {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526},
      {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640},
  }};
  static const std::array<std::array<double, 5>, 5> weights{{
      {2.0},
      {1.0, 1.0},
      {0.5555555555555556, 0.8888888888888888, 0.5555555555555556},
      {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538},
      {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
       0.2369268850561891},
  }};
  if (n < 1 || n > 5) {
    throw std::invalid_argument(fmt::format(
        "{}: thickness_points = {}: allowed 1..5 (Gauss-Legendre points through the thickness)",
        source, n));
  }
  model.thickness_points = n;
  model.gauss_points = points[n - 1];
  model.gauss_weights = weights[n - 1];
}

Eigen::Vector3d node(const Mesh& mesh, std::int64_t i) { return mesh.nodes.col(i); }

// Gradient of the linear function through three points with the given values.
Eigen::Vector2d linear_gradient(const std::array<Eigen::Vector2d, 3>& q, const std::array<double, 3>& v) {
  Eigen::Matrix2d A;
  A.row(0) = (q[1] - q[0]).transpose();
  A.row(1) = (q[2] - q[0]).transpose();
  return A.inverse() * Eigen::Vector2d(v[1] - v[0], v[2] - v[0]);
}

}  // namespace

ShellModel build_shell_model(const Mesh& mesh, const ShellModelOptions& options,
                             const std::string& source) {
  ShellModel model;
  set_gauss_rule(options.thickness_points, model, source);
  model.density = options.density;
  model.reference_positions = mesh.nodes;
  const std::int64_t num_nodes = mesh.num_nodes();
  model.nodal_mass = Eigen::VectorXd::Zero(num_nodes);
  model.fixed.assign(static_cast<std::size_t>(num_nodes), 0);
  for (const std::int64_t n : options.fixed_nodes) {
    if (n < 0 || n >= num_nodes) {
      throw std::invalid_argument(
          fmt::format("{}: fixed node {} does not exist (mesh has {} nodes)", source, n, num_nodes));
    }
    model.fixed[static_cast<std::size_t>(n)] = 1;
  }

  for (const Plane& plane : options.symmetry_planes) model.mirror_planes.push_back({plane.point, plane.normal.normalized()});
  const double model_size = (mesh.nodes.rowwise().maxCoeff() - mesh.nodes.rowwise().minCoeff()).norm();
  const auto plane_of_edge = [&](std::int64_t a, std::int64_t b) -> int {
    for (std::size_t k = 0; k < model.mirror_planes.size(); ++k) {
      const Plane& plane = model.mirror_planes[k];
      const double da = (mesh.nodes.col(a) - plane.point).dot(plane.normal);
      const double db = (mesh.nodes.col(b) - plane.point).dot(plane.normal);
      if (std::abs(da) <= 1e-6 * model_size && std::abs(db) <= 1e-6 * model_size) return static_cast<int>(k);
    }
    return -1;
  };

  // Directed edge (a -> b) to (triangle, local edge index) for neighbour search.
  std::map<std::pair<std::int64_t, std::int64_t>, std::pair<std::int64_t, int>> directed;
  const std::int64_t num_triangles = mesh.num_triangles();
  for (std::int64_t t = 0; t < num_triangles; ++t) {
    const auto& tri = mesh.triangles[static_cast<std::size_t>(t)];
    for (int i = 0; i < 3; ++i) {
      const auto key = std::make_pair(tri[(i + 1) % 3], tri[(i + 2) % 3]);
      if (!directed.emplace(key, std::make_pair(t, i)).second) {
        throw std::invalid_argument(fmt::format(
            "{}: edge ({}, {}) is used twice in the same direction (triangles {} and {}): the "
            "leaflet surface must be manifold and consistently oriented",
            source, key.first, key.second, directed[key].first, t));
      }
    }
  }

  model.elements.resize(static_cast<std::size_t>(num_triangles));
  for (std::int64_t t = 0; t < num_triangles; ++t) {
    const auto& tri = mesh.triangles[static_cast<std::size_t>(t)];
    ShellElement& el = model.elements[static_cast<std::size_t>(t)];
    for (int a = 0; a < 3; ++a) el.nodes[a] = static_cast<std::int32_t>(tri[a]);
    const Eigen::Vector3d X0 = node(mesh, tri[0]), X1 = node(mesh, tri[1]), X2 = node(mesh, tri[2]);
    const Eigen::Vector3d raw_normal = (X1 - X0).cross(X2 - X0);
    el.area = 0.5 * raw_normal.norm();
    if (!(el.area > 0.0)) {
      throw std::invalid_argument(fmt::format("{}: triangle {} has zero area", source, t));
    }
    el.reference_normal = raw_normal.normalized();
    el.thickness = mesh.triangle_thickness[static_cast<std::size_t>(t)];
    // Material frame: circumferential axis projected into the element plane.
    Eigen::Vector3d c = mesh.triangle_circumferential.col(t);
    c -= c.dot(el.reference_normal) * el.reference_normal;
    if (c.norm() < 1e-6) {
      throw std::invalid_argument(fmt::format(
          "{}: /mesh/triangle_axes/circumferential[{}] is normal to the triangle", source, t));
    }
    el.circumferential = c.normalized();
    el.radial = el.reference_normal.cross(el.circumferential);

    const std::array<Eigen::Vector3d, 3> X{X0, X1, X2};
    std::array<Eigen::Vector2d, 3> p;
    for (int a = 0; a < 3; ++a) {
      p[a] = {(X[a] - X0).dot(el.circumferential), (X[a] - X0).dot(el.radial)};
    }
    const double twice_area = (p[1] - p[0]).x() * (p[2] - p[0]).y() - (p[1] - p[0]).y() * (p[2] - p[0]).x();
    for (int a = 0; a < 3; ++a) {
      const Eigen::Vector2d& pb = p[(a + 1) % 3];
      const Eigen::Vector2d& pc = p[(a + 2) % 3];
      el.shape_gradients.row(a) = Eigen::Vector2d(pb.y() - pc.y(), pc.x() - pb.x()) / twice_area;
    }
    double longest_edge = 0.0;
    for (int a = 0; a < 3; ++a) longest_edge = std::max(longest_edge, (X[(a + 1) % 3] - X[(a + 2) % 3]).norm());
    el.min_height = 2.0 * el.area / longest_edge;

    // Row i of the curvature recovery: the fold angle across edge i of the exact quadratic
    // surface w = x.kappa.x / 2 with unit kappa components, interpolated linearly on the
    // triangles (so constant curvature is recovered exactly on any mesh).
    const std::array<Eigen::Matrix2d, 3> unit_kappa{
        (Eigen::Matrix2d() << 1, 0, 0, 0).finished(), (Eigen::Matrix2d() << 0, 0, 0, 1).finished(),
        (Eigen::Matrix2d() << 0, 0.5, 0.5, 0).finished()};
    Eigen::Matrix3d rows;
    for (int i = 0; i < 3; ++i) {
      const int ia = (i + 1) % 3, ib = (i + 2) % 3;
      const std::int64_t a = tri[ia], b = tri[ib];
      const Eigen::Vector2d edge2 = (p[ib] - p[ia]).normalized();
      const Eigen::Vector2d outward{edge2.y(), -edge2.x()};  // counter-clockwise triangle: right of the edge
      const Eigen::Vector2d midpoint = 0.5 * (p[ia] + p[ib]);
      const auto found = directed.find({b, a});
      const bool both_fixed = model.fixed[static_cast<std::size_t>(a)] && model.fixed[static_cast<std::size_t>(b)];
      if (found != directed.end()) {
        const auto& ntri = mesh.triangles[static_cast<std::size_t>(found->second.first)];
        const std::int64_t opp = ntri[found->second.second];
        el.opposite[i] = static_cast<std::int32_t>(opp);
        el.neighbour[i] = static_cast<std::int32_t>(found->second.first);
        el.neighbour_slot[i] = static_cast<std::int8_t>(found->second.second);
        el.edge_kind[i] = EdgeKind::interior;
        // Unfold the neighbour into this element's plane.
        const Eigen::Vector3d Xa = node(mesh, a), Xb = node(mesh, b), Xo = node(mesh, opp);
        const Eigen::Vector3d e_hat = (Xb - Xa).normalized();
        const double along = (Xo - Xa).dot(e_hat);
        const double height = ((Xo - Xa) - along * e_hat).norm();
        const Eigen::Vector2d po = p[ia] + along * edge2 + height * outward;
        for (int J = 0; J < 3; ++J) {
          const auto w = [&](const Eigen::Vector2d& q) { return 0.5 * (q - midpoint).dot(unit_kappa[J] * (q - midpoint)); };
          const Eigen::Vector2d g_own = linear_gradient({p[ia], p[ib], p[i]}, {w(p[ia]), w(p[ib]), w(p[i])});
          const Eigen::Vector2d g_other = linear_gradient({p[ia], p[ib], po}, {w(p[ia]), w(p[ib]), w(po)});
          rows(i, J) = (g_other - g_own).dot(outward);
        }
        const HingeSide sa = hinge_side(Xa, Xb, X[i], false);
        const HingeSide sb = hinge_side(Xa, Xb, Xo, true);
        el.reference_fold_angle[i] = fold_angle(sa, sb, Xa, Xb);
      } else if (both_fixed && options.clamp_fixed_edges) {
        el.edge_kind[i] = EdgeKind::clamped;
        // The support keeps zero slope at the edge; w has zero slope at the edge midpoint.
        for (int J = 0; J < 3; ++J) {
          const auto w = [&](const Eigen::Vector2d& q) { return 0.5 * (q - midpoint).dot(unit_kappa[J] * (q - midpoint)); };
          const Eigen::Vector2d g_own = linear_gradient({p[ia], p[ib], p[i]}, {w(p[ia]), w(p[ib]), w(p[i])});
          rows(i, J) = -g_own.dot(outward);
        }
      } else if (const int k = plane_of_edge(a, b); k >= 0) {
        el.edge_kind[i] = EdgeKind::mirror;
        el.mirror_plane[i] = static_cast<std::int8_t>(k);
        // The mirror image of this triangle, unfolded: its vertex reflected across the edge line.
        const Eigen::Vector2d foot = p[ia] + (p[i] - p[ia]).dot(edge2) * edge2;
        const Eigen::Vector2d po = 2.0 * foot - p[i];
        for (int J = 0; J < 3; ++J) {
          const auto w = [&](const Eigen::Vector2d& q) { return 0.5 * (q - midpoint).dot(unit_kappa[J] * (q - midpoint)); };
          const Eigen::Vector2d g_own = linear_gradient({p[ia], p[ib], p[i]}, {w(p[ia]), w(p[ib]), w(p[i])});
          const Eigen::Vector2d g_other = linear_gradient({p[ia], p[ib], po}, {w(p[ia]), w(p[ib]), w(po)});
          rows(i, J) = (g_other - g_own).dot(outward);
        }
        const Plane& plane = model.mirror_planes[static_cast<std::size_t>(k)];
        const Eigen::Vector3d Xa = node(mesh, a), Xb = node(mesh, b);
        const Eigen::Vector3d ghost = X[i] - 2.0 * (X[i] - plane.point).dot(plane.normal) * plane.normal;
        el.reference_fold_angle[i] =
            fold_angle(hinge_side(Xa, Xb, X[i], false), hinge_side(Xa, Xb, ghost, true), Xa, Xb);
      } else {
        el.edge_kind[i] = EdgeKind::free;
        // Zero normal curvature across a free edge: t.kappa.t = 0.
        rows.row(i) << outward.x() * outward.x(), outward.y() * outward.y(), outward.x() * outward.y();
      }
    }
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(rows);
    if (!lu.isInvertible()) {
      throw std::invalid_argument(fmt::format(
          "{}: triangle {}: curvature cannot be recovered from its edges (degenerate patch)", source, t));
    }
    el.curvature_from_angles = lu.inverse();

    const double mass = options.density * el.thickness * el.area / 3.0;
    for (int a = 0; a < 3; ++a) model.nodal_mass(tri[a]) += mass;
  }
  return model;
}

}  // namespace valvefsi::solid
