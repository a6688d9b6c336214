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
  if (edges_for_ != triangles.size()) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::size_t> index;
    edges_.clear();
    for (std::size_t t = 0; t < triangles.size(); ++t)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t i = triangles[t][static_cast<std::size_t>(k)], j = triangles[t][static_cast<std::size_t>((k + 1) % 3)];
        const auto key = std::make_pair(std::min(i, j), std::max(i, j));
        auto [it, inserted] = index.try_emplace(key, edges_.size());
        if (inserted) edges_.push_back(Edge{key.first, key.second, {}});
        edges_[it->second].users.push_back({static_cast<std::uint32_t>(t), k});
      }
    edges_for_ = triangles.size();
  }
  std::vector<Vec3> face(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    face[t] = face_normal(t);
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t i = triangles[t][static_cast<std::size_t>(k)];
      // Angle of the triangle at corner k weights its normal at that vertex.
      const Vec3 u = sub(corner(*this, t, (k + 1) % 3), corner(*this, t, k));
      const Vec3 v = sub(corner(*this, t, (k + 2) % 3), corner(*this, t, k));
      const double angle = std::acos(std::clamp(dot(u, v) / (norm(u) * norm(v)), -1.0, 1.0));
      vertex_normal[i] = add(vertex_normal[i], scale(face[t], angle));
    }
  }
  for (const Edge& e : edges_) {
    Vec3 sum{0, 0, 0};
    for (const auto& [t, k] : e.users) sum = add(sum, face[t]);
    for (const auto& [t, k] : e.users) {
      edge_normal[t][static_cast<std::size_t>(k)] = sum;
      edge_on_boundary[t][static_cast<std::size_t>(k)] = e.users.size() == 1;
    }
    if (e.users.size() == 1) vertex_on_boundary[e.first] = vertex_on_boundary[e.second] = true;
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

namespace {

// Moller & Trumbore (1997) for triangle t; a segment in the triangle's plane does not cross it.
bool segment_meets_triangle(const TriangleMesh& mesh, std::size_t t, const Vec3& p, const Vec3& d, double d_norm,
                            Crossing3& hit) {
  constexpr double tol = 1e-12;
  const Vec3 a = corner(mesh, t, 0);
  const Vec3 e1 = sub(corner(mesh, t, 1), a), e2 = sub(corner(mesh, t, 2), a);
  const Vec3 h = cross(d, e2);
  const double det = dot(e1, h);
  if (std::abs(det) <= 1e-14 * d_norm * norm(e1) * norm(e2)) return false;
  const double f = 1.0 / det;
  const Vec3 s = sub(p, a);
  const double u = f * dot(s, h);
  if (u < -tol || u > 1 + tol) return false;
  const Vec3 qv = cross(s, e1);
  const double v = f * dot(d, qv);
  if (v < -tol || u + v > 1 + tol) return false;
  const double along = f * dot(e2, qv);
  if (along < -tol || along > 1 + tol) return false;
  hit = Crossing3{t, along, {1 - u - v, u, v}};
  return true;
}

}  // namespace

std::optional<Crossing3> first_crossing(const TriangleMesh& mesh, const std::vector<std::uint32_t>& triangles, const Vec3& p,
                                        const Vec3& q) {
  std::optional<Crossing3> best;
  const Vec3 d = sub(q, p);
  const double dn = norm(d);
  Crossing3 hit;
  for (const std::uint32_t t : triangles)
    if (segment_meets_triangle(mesh, t, p, d, dn, hit) && (!best || hit.s < best->s)) best = hit;
  return best;
}

std::optional<Crossing3> crossing(const TriangleMesh& mesh, std::size_t t, const Vec3& p, const Vec3& q) {
  const Vec3 d = sub(q, p);
  Crossing3 hit;
  if (segment_meets_triangle(mesh, t, p, d, norm(d), hit)) return hit;
  return std::nullopt;
}

std::optional<Crossing3> first_crossing(const TriangleMesh& mesh, const Vec3& p, const Vec3& q) {
  std::optional<Crossing3> best;
  const Vec3 d = sub(q, p);
  const double dn = norm(d);
  Crossing3 hit;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    if (segment_meets_triangle(mesh, t, p, d, dn, hit) && (!best || hit.s < best->s)) best = hit;
  return best;
}

std::optional<SweptCrossing3> swept_crossing(const TriangleMesh& mesh, const std::vector<Vec3>& before,
                                             const std::vector<Vec3>& after, const Vec3& x0, const Vec3& x1) {
  std::vector<std::uint32_t> all(mesh.triangles.size());
  for (std::size_t t = 0; t < all.size(); ++t) all[t] = static_cast<std::uint32_t>(t);
  return swept_crossing(mesh, all, before, after, x0, x1);
}

std::optional<SweptCrossing3> swept_crossing(const TriangleMesh& mesh, const std::vector<std::uint32_t>& triangles,
                                             const std::vector<Vec3>& before, const std::vector<Vec3>& after, const Vec3& x0,
                                             const Vec3& x1) {
  std::vector<SweptCrossing3> events;
  const Vec3 dx = sub(x1, x0);
  for (const std::uint32_t t : triangles) {
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

void TriangleBuckets::build(const std::vector<std::array<Vec3, 2>>& boxes, double cell_size) {
  Vec3 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  Vec3 hi{-lo[0], -lo[1], -lo[2]};
  for (const auto& b : boxes)
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], b[0][d]);
      hi[d] = std::max(hi[d], b[1][d]);
    }
  if (boxes.empty()) lo = hi = {0, 0, 0};
  origin_ = lo;
  inv_cell_ = 1.0 / cell_size;
  near_start_.clear();  // the neighbourhoods of the last build
  near_items_.clear();
  for (int d = 0; d < 3; ++d) count_[d] = std::max(1, static_cast<int>(std::floor((hi[d] - lo[d]) * inv_cell_)) + 1);
  const std::size_t cells = static_cast<std::size_t>(count_[0]) * static_cast<std::size_t>(count_[1]) * static_cast<std::size_t>(count_[2]);
  start_.assign(cells + 1, 0);
  auto range = [&](const std::array<Vec3, 2>& b, std::array<int, 3>& l, std::array<int, 3>& u) {
    for (int d = 0; d < 3; ++d) {
      l[d] = std::clamp(static_cast<int>(std::floor((b[0][d] - origin_[d]) * inv_cell_)), 0, count_[d] - 1);
      u[d] = std::clamp(static_cast<int>(std::floor((b[1][d] - origin_[d]) * inv_cell_)), 0, count_[d] - 1);
    }
  };
  auto cell = [&](int i, int j, int k) {
    return (static_cast<std::size_t>(k) * static_cast<std::size_t>(count_[1]) + static_cast<std::size_t>(j)) *
               static_cast<std::size_t>(count_[0]) + static_cast<std::size_t>(i);
  };
  std::array<int, 3> l{}, u{};
  for (const auto& b : boxes) {  // counting pass, then fill (CSR)
    range(b, l, u);
    for (int k = l[2]; k <= u[2]; ++k)
      for (int j = l[1]; j <= u[1]; ++j)
        for (int i = l[0]; i <= u[0]; ++i) ++start_[cell(i, j, k) + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
  items_.assign(start_[cells], 0);
  std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
  for (std::size_t t = 0; t < boxes.size(); ++t) {
    range(boxes[t], l, u);
    for (int k = l[2]; k <= u[2]; ++k)
      for (int j = l[1]; j <= u[1]; ++j)
        for (int i = l[0]; i <= u[0]; ++i) items_[fill[cell(i, j, k)]++] = static_cast<std::uint32_t>(t);
  }
}

bool TriangleBuckets::cell_range(const Vec3& lower, const Vec3& upper, std::array<int, 3>& l, std::array<int, 3>& u) const {
  for (int d = 0; d < 3; ++d) {
    const double a = std::floor((lower[d] - origin_[d]) * inv_cell_), b = std::floor((upper[d] - origin_[d]) * inv_cell_);
    if (b < 0 || a > count_[d] - 1) return false;  // outside the grid: no triangle there
    l[d] = static_cast<int>(std::max(a, 0.0));
    u[d] = static_cast<int>(std::min(b, static_cast<double>(count_[d] - 1)));
  }
  return true;
}

void TriangleBuckets::query(const Vec3& lower, const Vec3& upper, std::vector<std::uint32_t>& out) const {
  out.clear();
  if (start_.empty()) return;
  std::array<int, 3> l{}, u{};
  if (!cell_range(lower, upper, l, u)) return;
  for (int k = l[2]; k <= u[2]; ++k)
    for (int j = l[1]; j <= u[1]; ++j)
      for (int i = l[0]; i <= u[0]; ++i) {
        const std::size_t c = cell_index(i, j, k);
        out.insert(out.end(), items_.begin() + start_[c], items_.begin() + start_[c + 1]);
      }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

void TriangleBuckets::cache_neighbourhoods() {
  near_start_.clear();
  near_items_.clear();
  if (start_.empty()) return;
  near_start_.reserve(start_.size());
  near_start_.push_back(0);
  std::vector<std::uint32_t> list;
  for (int k = 0; k < count_[2]; ++k)  // in cell_index order
    for (int j = 0; j < count_[1]; ++j)
      for (int i = 0; i < count_[0]; ++i) {
        list.clear();
        for (int kk = std::max(k - 1, 0); kk <= std::min(k + 1, count_[2] - 1); ++kk)
          for (int jj = std::max(j - 1, 0); jj <= std::min(j + 1, count_[1] - 1); ++jj)
            for (int ii = std::max(i - 1, 0); ii <= std::min(i + 1, count_[0] - 1); ++ii) {
              const std::size_t c = cell_index(ii, jj, kk);
              list.insert(list.end(), items_.begin() + start_[c], items_.begin() + start_[c + 1]);
            }
        std::sort(list.begin(), list.end());
        list.erase(std::unique(list.begin(), list.end()), list.end());
        near_items_.insert(near_items_.end(), list.begin(), list.end());
        near_start_.push_back(static_cast<std::uint32_t>(near_items_.size()));
      }
}

std::span<const std::uint32_t> TriangleBuckets::around(const Vec3& lower, const Vec3& upper, std::vector<std::uint32_t>& scratch) const {
  std::array<int, 3> l{}, u{};
  if (start_.empty() || !cell_range(lower, upper, l, u)) return {};  // query() finds none
  if (!near_start_.empty()) {
    std::array<int, 3> c{};
    bool covered = true;
    for (int d = 0; d < 3; ++d) {
      const double centre = std::floor((0.5 * (lower[d] + upper[d]) - origin_[d]) * inv_cell_);
      c[d] = static_cast<int>(std::clamp(centre, 0.0, static_cast<double>(count_[d] - 1)));
      // The box's cells as query() rounds them, not as the centre's cell suggests.
      covered = covered && l[d] >= c[d] - 1 && u[d] <= c[d] + 1;
    }
    if (covered) {
      const std::size_t n = cell_index(c[0], c[1], c[2]);
      return {near_items_.data() + near_start_[n], near_start_[n + 1] - near_start_[n]};
    }
  }
  query(lower, upper, scratch);
  return scratch;
}

std::vector<std::array<Vec3, 2>> triangle_boxes(const TriangleMesh& mesh, const std::vector<Vec3>* other) {
  std::vector<std::array<Vec3, 2>> boxes(mesh.triangles.size());
  for (std::size_t t = 0; t < boxes.size(); ++t) {
    auto& b = boxes[t];
    b[0] = b[1] = mesh.position[mesh.triangles[t][0]];
    for (const auto* nodes : {&mesh.position, other}) {
      if (nodes == nullptr) continue;
      for (const std::uint32_t n : mesh.triangles[t])
        for (int d = 0; d < 3; ++d) {
          b[0][d] = std::min(b[0][d], (*nodes)[n][d]);
          b[1][d] = std::max(b[1][d], (*nodes)[n][d]);
        }
    }
  }
  return boxes;
}

namespace {

void triangles_within_boxed(const TriangleMesh& mesh, const std::vector<std::array<Vec3, 2>>* boxes,
                            std::span<const std::uint32_t> candidates, const Vec3& x, double radius, std::vector<std::uint32_t>& out,
                            std::vector<double>& distances) {
  out.clear();
  distances.clear();
  thread_local std::vector<std::pair<double, std::uint32_t>> found;
  found.clear();
  // A triangle is no nearer than its box; the margin keeps every triangle whose rounded
  // distance could fall below the radius (rounding is ~1e-15 of it).
  const double box_reject2 = radius * radius * (1.0 + 1e-9);
  for (const std::uint32_t t : candidates) {
    if (boxes != nullptr) {
      const auto& b = (*boxes)[t];
      double g2 = 0.0;
      for (int d = 0; d < 3; ++d) {
        const double g = std::max({b[0][d] - x[d], x[d] - b[1][d], 0.0});
        g2 += g * g;
      }
      if (g2 > box_reject2) continue;
    }
    const TrianglePoint tp = closest_on_triangle(x, corner(mesh, t, 0), corner(mesh, t, 1), corner(mesh, t, 2));
    Vec3 point{0, 0, 0};
    for (int k = 0; k < 3; ++k) point = add(point, scale(corner(mesh, t, k), tp.barycentric[static_cast<std::size_t>(k)]));
    const Vec3 r = sub(x, point);
    const double d2 = dot(r, r);
    if (d2 < radius * radius) found.push_back({d2, t});
  }
  // By (distance, triangle): the answer does not depend on the candidates' order or extras.
  std::sort(found.begin(), found.end());
  for (const auto& [d2, t] : found) {
    out.push_back(t);
    distances.push_back(std::sqrt(d2));
  }
}

}  // namespace

void triangles_within(const TriangleMesh& mesh, const std::vector<std::uint32_t>& candidates, const Vec3& x, double radius,
                      std::vector<std::uint32_t>& out) {
  thread_local std::vector<double> distances;
  triangles_within(mesh, candidates, x, radius, out, distances);
}

void triangles_within(const TriangleMesh& mesh, const std::vector<std::uint32_t>& candidates, const Vec3& x, double radius,
                      std::vector<std::uint32_t>& out, std::vector<double>& distances) {
  triangles_within_boxed(mesh, nullptr, candidates, x, radius, out, distances);
}

void triangles_within(const TriangleMesh& mesh, const std::vector<std::array<Vec3, 2>>& boxes,
                      std::span<const std::uint32_t> candidates, const Vec3& x, double radius, std::vector<std::uint32_t>& out,
                      std::vector<double>& distances) {
  triangles_within_boxed(mesh, &boxes, candidates, x, radius, out, distances);
}

}  // namespace valvefsi::fluid::thin_wall
