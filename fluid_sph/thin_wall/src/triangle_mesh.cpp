#include "valvefsi/fluid/thin_wall/triangle_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

namespace valvefsi::fluid::thin_wall {
namespace {

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Vec3 scale(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

// Closest point of triangle (a, b, c) to p by the Voronoi region of its features.
// feature: 0-2 vertex k, 3-5 edge (k - 3) joining corners k - 3 and (k - 2) % 3, 6 the face.
struct TrianglePoint {
  Vec3 barycentric;
  int feature;
};

TrianglePoint closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return {{1, 0, 0}, 0};
  const Vec3 bp = sub(p, b);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return {{0, 1, 0}, 1};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return {{1 - v, v, 0}, 3};
  }
  const Vec3 cp = sub(p, c);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return {{0, 0, 1}, 2};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return {{1 - w, 0, w}, 5};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {{0, 1 - w, w}, 4};
  }
  const double inv = 1.0 / (va + vb + vc);
  const double v = vb * inv, w = vc * inv;
  return {{1 - v - w, v, w}, 6};
}

Vec3 corner(const TriangleMesh& m, std::size_t t, int k) { return m.position[m.triangles[t][static_cast<std::size_t>(k)]]; }

}  // namespace

Vec3 TriangleMesh::face_normal(std::size_t t) const {
  const Vec3 n = cross(sub(corner(*this, t, 1), corner(*this, t, 0)), sub(corner(*this, t, 2), corner(*this, t, 0)));
  return scale(n, 1.0 / norm(n));
}

void TriangleMesh::update() {
  vertex_normal.assign(position.size(), Vec3{0, 0, 0});
  vertex_on_boundary.assign(position.size(), false);
  edge_normal.assign(triangles.size(), {});
  edge_on_boundary.assign(triangles.size(), {});
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::pair<std::size_t, int>>> edges;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Vec3 n = face_normal(t);
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t i = triangles[t][static_cast<std::size_t>(k)], j = triangles[t][static_cast<std::size_t>((k + 1) % 3)];
      edges[{std::min(i, j), std::max(i, j)}].push_back({t, k});
      // Angle of the triangle at corner k weights its normal at that vertex.
      const Vec3 u = sub(corner(*this, t, (k + 1) % 3), corner(*this, t, k));
      const Vec3 v = sub(corner(*this, t, (k + 2) % 3), corner(*this, t, k));
      const double angle = std::acos(std::clamp(dot(u, v) / (norm(u) * norm(v)), -1.0, 1.0));
      vertex_normal[i] = add(vertex_normal[i], scale(n, angle));
    }
  }
  for (const auto& [key, users] : edges) {
    Vec3 sum{0, 0, 0};
    for (const auto& [t, k] : users) sum = add(sum, face_normal(t));
    for (const auto& [t, k] : users) {
      edge_normal[t][static_cast<std::size_t>(k)] = sum;
      edge_on_boundary[t][static_cast<std::size_t>(k)] = users.size() == 1;
    }
    if (users.size() == 1) vertex_on_boundary[key.first] = vertex_on_boundary[key.second] = true;
  }
}

ClosestPoint3 closest_point(const TriangleMesh& mesh, const std::vector<std::uint32_t>& candidates, const Vec3& x) {
  ClosestPoint3 best;
  best.distance = std::numeric_limits<double>::infinity();
  int best_feature = 6;
  for (const std::uint32_t t : candidates) {
    const TrianglePoint tp = closest_on_triangle(x, corner(mesh, t, 0), corner(mesh, t, 1), corner(mesh, t, 2));
    Vec3 point{0, 0, 0};
    for (int k = 0; k < 3; ++k) point = add(point, scale(corner(mesh, t, k), tp.barycentric[static_cast<std::size_t>(k)]));
    const double d = norm(sub(x, point));
    if (d < best.distance) {
      best.triangle = t;
      best.barycentric = tp.barycentric;
      best.point = point;
      best.distance = d;
      best_feature = tp.feature;
    }
  }
  // Side from the pseudo-normal of the nearest feature (exact for any dihedral angle).
  const std::size_t t = best.triangle;
  Vec3 n;
  if (best_feature < 3) {
    const std::uint32_t v = mesh.triangles[t][static_cast<std::size_t>(best_feature)];
    n = mesh.vertex_normal[v];
    best.on_boundary = mesh.vertex_on_boundary[v];
  } else if (best_feature < 6) {
    n = mesh.edge_normal[t][static_cast<std::size_t>(best_feature - 3)];
    best.on_boundary = mesh.edge_on_boundary[t][static_cast<std::size_t>(best_feature - 3)];
  } else {
    n = mesh.face_normal(t);
  }
  best.side = dot(sub(x, best.point), n) >= 0 ? 1 : -1;
  return best;
}

ClosestPoint3 closest_point(const TriangleMesh& mesh, const Vec3& x) {
  std::vector<std::uint32_t> all(mesh.triangles.size());
  for (std::size_t t = 0; t < all.size(); ++t) all[t] = static_cast<std::uint32_t>(t);
  return closest_point(mesh, all, x);
}

std::optional<Crossing3> first_crossing(const TriangleMesh& mesh, const Vec3& p, const Vec3& q) {
  // Moller & Trumbore (1997) per triangle; a segment in a triangle's plane does not cross it.
  std::optional<Crossing3> best;
  const Vec3 d = sub(q, p);
  constexpr double tol = 1e-12;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Vec3 a = corner(mesh, t, 0);
    const Vec3 e1 = sub(corner(mesh, t, 1), a), e2 = sub(corner(mesh, t, 2), a);
    const Vec3 h = cross(d, e2);
    const double det = dot(e1, h);
    if (std::abs(det) <= 1e-14 * norm(d) * norm(e1) * norm(e2)) continue;
    const double f = 1.0 / det;
    const Vec3 s = sub(p, a);
    const double u = f * dot(s, h);
    if (u < -tol || u > 1 + tol) continue;
    const Vec3 qv = cross(s, e1);
    const double v = f * dot(d, qv);
    if (v < -tol || u + v > 1 + tol) continue;
    const double along = f * dot(e2, qv);
    if (along < -tol || along > 1 + tol) continue;
    if (!best || along < best->s) best = Crossing3{t, along};
  }
  return best;
}

std::optional<SweptCrossing3> swept_crossing(const TriangleMesh& mesh, const std::vector<Vec3>& before,
                                             const std::vector<Vec3>& after, const Vec3& x0, const Vec3& x1) {
  std::vector<SweptCrossing3> events;
  const Vec3 dx = sub(x1, x0);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Vec3 a0 = before[tri[0]], da = sub(after[tri[0]], a0);
    const Vec3 e1 = sub(before[tri[1]], a0), de1 = sub(sub(after[tri[1]], before[tri[1]]), da);
    const Vec3 e2 = sub(before[tri[2]], a0), de2 = sub(sub(after[tri[2]], before[tri[2]]), da);
    const Vec3 w = sub(x0, a0), dw = sub(dx, da);
    // (e1 + tau de1) x (e2 + tau de2) . (w + tau dw) = k0 + k1 tau + k2 tau^2 + k3 tau^3.
    const Vec3 n0 = cross(e1, e2), n1 = add(cross(e1, de2), cross(de1, e2)), n2 = cross(de1, de2);
    const double k0 = dot(n0, w), k1 = dot(n0, dw) + dot(n1, w), k2 = dot(n1, dw) + dot(n2, w), k3 = dot(n2, dw);
    auto f = [&](double tau) { return ((k3 * tau + k2) * tau + k1) * tau + k0; };
    // Monotone pieces between the roots of f' = k1 + 2 k2 tau + 3 k3 tau^2, then bisection.
    std::vector<double> cuts{0.0, 1.0};
    const double qa = 3 * k3, qb = 2 * k2, qc = k1;
    if (std::abs(qa) > 0) {
      const double disc = qb * qb - 4 * qa * qc;
      if (disc >= 0) {
        for (const double r : {(-qb - std::sqrt(disc)) / (2 * qa), (-qb + std::sqrt(disc)) / (2 * qa)})
          if (r > 0 && r < 1) cuts.push_back(r);
      }
    } else if (std::abs(qb) > 0) {
      const double r = -qc / qb;
      if (r > 0 && r < 1) cuts.push_back(r);
    }
    std::sort(cuts.begin(), cuts.end());
    for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
      double lo = cuts[k], hi = cuts[k + 1];
      const double flo = f(lo), fhi = f(hi);
      // Sign change (zero counts as the positive side, so touching and leaving is no event).
      if ((flo >= 0) == (fhi >= 0)) continue;
      for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        if ((f(mid) >= 0) == (flo >= 0)) lo = mid;
        else hi = mid;
      }
      const double tau = 0.5 * (lo + hi);
      // Inside the triangle at that moment (barycentric, with a small tolerance).
      const Vec3 a = add(a0, scale(da, tau));
      const Vec3 u = add(e1, scale(de1, tau)), v = add(e2, scale(de2, tau)), p = sub(add(x0, scale(dx, tau)), a);
      const double uu = dot(u, u), uv = dot(u, v), vv = dot(v, v), pu = dot(p, u), pv = dot(p, v);
      const double den = uu * vv - uv * uv;
      const double bu = (vv * pu - uv * pv) / den, bv = (uu * pv - uv * pu) / den;
      constexpr double tol = 1e-10;
      if (bu >= -tol && bv >= -tol && bu + bv <= 1 + tol) events.push_back({t, tau});
    }
  }
  // An event on an edge shared by two triangles is found twice: count it once.
  std::sort(events.begin(), events.end(), [](const auto& l, const auto& r) { return l.tau < r.tau; });
  std::vector<SweptCrossing3> unique;
  for (const auto& e : events)
    if (unique.empty() || e.tau - unique.back().tau > 1e-9) unique.push_back(e);
  if (unique.size() % 2 == 0) return std::nullopt;
  return unique.front();
}

}  // namespace valvefsi::fluid::thin_wall
