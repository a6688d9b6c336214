#include "valvefsi/fluid/thin_wall/polyline.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace valvefsi::fluid::thin_wall {
namespace {

Vec2 sub(const Vec2& a, const Vec2& b) { return {a[0] - b[0], a[1] - b[1]}; }
double dot(const Vec2& a, const Vec2& b) { return a[0] * b[0] + a[1] * b[1]; }
double cross(const Vec2& a, const Vec2& b) { return a[0] * b[1] - a[1] * b[0]; }
Vec2 lerp(const Vec2& a, const Vec2& b, double t) { return {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])}; }

struct SegmentPoint {
  double t;
  double distance2;
};

SegmentPoint closest_on_segment(const Vec2& a, const Vec2& b, const Vec2& x) {
  const Vec2 e = sub(b, a);
  const double t = std::clamp(dot(sub(x, a), e) / dot(e, e), 0.0, 1.0);
  const Vec2 c = lerp(a, b, t);
  const Vec2 d = sub(x, c);
  return {t, dot(d, d)};
}

// Side of x for the closest point (segment k, parameter t); see ClosestPoint::side.
ClosestPoint finish(const Polyline& wall, std::size_t k, double t, double distance2, const Vec2& x) {
  ClosestPoint c;
  c.segment = k;
  c.t = t;
  c.point = wall.point(k, t);
  c.distance = std::sqrt(distance2);
  const std::size_t last = wall.segment_count() - 1;
  const Vec2 d = sub(x, c.point);
  Vec2 n = wall.normal(k);
  if (t <= 0.0 && k > 0) {
    const Vec2 m = wall.normal(k - 1);
    n = {n[0] + m[0], n[1] + m[1]};
  } else if (t >= 1.0 && k < last) {
    const Vec2 m = wall.normal(k + 1);
    n = {n[0] + m[0], n[1] + m[1]};
  }
  c.at_free_end = (t <= 0.0 && k == 0) || (t >= 1.0 && k == last);
  if (c.at_free_end) n = wall.normal(k);  // beyond a tip: the side of the end segment's line
  c.side = dot(d, n) >= 0.0 ? 1 : -1;
  return c;
}

template <class SegmentRange>
ClosestPoint closest_over(const Polyline& wall, const SegmentRange& segments, const Vec2& x) {
  double best = std::numeric_limits<double>::infinity();
  std::size_t best_k = 0;
  double best_t = 0.0;
  for (const auto k : segments) {
    const SegmentPoint sp = closest_on_segment(wall.position[k], wall.position[k + 1], x);
    if (sp.distance2 < best) {
      best = sp.distance2;
      best_k = k;
      best_t = sp.t;
    }
  }
  return finish(wall, best_k, best_t, best, x);
}

struct AllSegments {
  std::size_t n;
  struct Iterator {
    std::size_t k;
    std::size_t operator*() const { return k; }
    Iterator& operator++() { ++k; return *this; }
    bool operator!=(const Iterator& o) const { return k != o.k; }
  };
  Iterator begin() const { return {0}; }
  Iterator end() const { return {n}; }
};

std::optional<Crossing> segment_meets(const Vec2& a, const Vec2& b, const Vec2& p, const Vec2& q) {
  const Vec2 r = sub(q, p);
  const Vec2 e = sub(b, a);
  const double denominator = cross(r, e);
  if (denominator == 0.0) return std::nullopt;  // parallel: a grazing pair is not blocked
  const Vec2 ap = sub(a, p);
  const double s = cross(ap, e) / denominator;
  const double t = cross(ap, r) / denominator;
  // Touching counts, with a margin far above round-off along the wall: a segment through an
  // interior node must meet one of its two segments whatever the rounding (without it such a
  // ray slipped through the node now and then, and the wall's rates jumped when it moved by an ulp).
  constexpr double margin = 1e-12;
  if (s < 0.0 || s > 1.0 || t < -margin || t > 1.0 + margin) return std::nullopt;
  return Crossing{0, t, s};
}

template <class SegmentRange>
std::optional<Crossing> first_crossing_over(const Polyline& wall, const SegmentRange& segments, const Vec2& p, const Vec2& q) {
  std::optional<Crossing> best;
  for (const auto k : segments) {
    auto c = segment_meets(wall.position[k], wall.position[k + 1], p, q);
    if (c && (!best || c->s < best->s)) {
      c->segment = k;
      best = c;
    }
  }
  return best;
}

// Real roots of c2 tau^2 + c1 tau + c0 = 0 in [0, 1] (at most two), in increasing order.
int roots_in_unit_interval(double c2, double c1, double c0, double roots[2]) {
  const double scale = std::max({std::abs(c2), std::abs(c1), std::abs(c0)});
  if (scale == 0.0) return 0;  // identically zero: moving along the wall's line, no crossing
  int n = 0;
  double r[2];
  if (std::abs(c2) <= 1e-12 * scale) {
    if (c1 == 0.0) return 0;
    r[n++] = -c0 / c1;
  } else {
    const double disc = c1 * c1 - 4.0 * c2 * c0;
    if (disc < 0.0) return 0;
    // Numerically stable pair of roots.
    const double qv = -0.5 * (c1 + std::copysign(std::sqrt(disc), c1));
    r[n++] = qv / c2;
    if (qv != 0.0) r[n++] = c0 / qv;
  }
  int kept = 0;
  for (int i = 0; i < n; ++i)
    if (r[i] >= 0.0 && r[i] <= 1.0) roots[kept++] = r[i];
  if (kept == 2 && roots[0] > roots[1]) std::swap(roots[0], roots[1]);
  return kept;
}

template <class SegmentRange>
std::optional<SweptCrossing> swept_over(const std::vector<Vec2>& before, const std::vector<Vec2>& after,
                                        const SegmentRange& segments, const Vec2& x0, const Vec2& x1) {
  if (before.size() != after.size() || before.size() < 2)
    throw std::invalid_argument("swept_crossing: node lists before (" + std::to_string(before.size()) + ") and after (" +
                                std::to_string(after.size()) + ") must have the same size >= 2");
  const std::size_t last = before.size() - 2;
  int events = 0;
  std::optional<SweptCrossing> first;
  for (const auto k : segments) {
    const Vec2 e0 = sub(before[k + 1], before[k]);
    const Vec2 de = sub(sub(after[k + 1], after[k]), e0);
    const Vec2 r0 = sub(x0, before[k]);
    const Vec2 dr = sub(sub(x1, after[k]), r0);
    const double c0 = cross(e0, r0);
    const double c1 = cross(e0, dr) + cross(de, r0);
    const double c2 = cross(de, dr);
    double roots[2];
    const int n = roots_in_unit_interval(c2, c1, c0, roots);
    for (int i = 0; i < n; ++i) {
      const double tau = roots[i];
      const Vec2 e = {e0[0] + tau * de[0], e0[1] + tau * de[1]};
      const Vec2 r = {r0[0] + tau * dr[0], r0[1] + tau * dr[1]};
      const double t = dot(r, e) / dot(e, e);
      // Half-open segments so that passing exactly through an interior node counts once.
      const bool inside = t >= 0.0 && (k == last ? t <= 1.0 : t < 1.0);
      if (!inside) continue;
      ++events;
      if (!first || tau < first->tau) first = SweptCrossing{k, tau, t};
    }
  }
  if (events % 2 == 0) return std::nullopt;
  return first;
}

}  // namespace

Polyline Polyline::at_rest(std::vector<Vec2> nodes) {
  if (nodes.size() < 2) throw std::invalid_argument("Polyline: needs at least 2 nodes, got " + std::to_string(nodes.size()));
  for (std::size_t k = 0; k + 1 < nodes.size(); ++k)
    if (nodes[k] == nodes[k + 1])
      throw std::invalid_argument("Polyline: nodes " + std::to_string(k) + " and " + std::to_string(k + 1) + " coincide");
  Polyline p;
  p.velocity.assign(nodes.size(), Vec2{0.0, 0.0});
  p.acceleration.assign(nodes.size(), Vec2{0.0, 0.0});
  p.position = std::move(nodes);
  return p;
}

double Polyline::segment_length(std::size_t k) const {
  const Vec2 e = sub(position[k + 1], position[k]);
  return std::sqrt(dot(e, e));
}

Vec2 Polyline::tangent(std::size_t k) const {
  const Vec2 e = sub(position[k + 1], position[k]);
  const double l = std::sqrt(dot(e, e));
  return {e[0] / l, e[1] / l};
}

Vec2 Polyline::normal(std::size_t k) const {
  const Vec2 t = tangent(k);
  return {-t[1], t[0]};
}

Vec2 Polyline::point(std::size_t k, double t) const { return lerp(position[k], position[k + 1], t); }
Vec2 Polyline::velocity_at(std::size_t k, double t) const { return lerp(velocity[k], velocity[k + 1], t); }
Vec2 Polyline::acceleration_at(std::size_t k, double t) const { return lerp(acceleration[k], acceleration[k + 1], t); }

ClosestPoint closest_point(const Polyline& wall, const Vec2& x) {
  return closest_over(wall, AllSegments{wall.segment_count()}, x);
}

ClosestPoint closest_point(const Polyline& wall, const std::vector<std::uint32_t>& segments, const Vec2& x) {
  if (segments.empty()) return closest_point(wall, x);
  return closest_over(wall, segments, x);
}

std::optional<Crossing> first_crossing(const Polyline& wall, const Vec2& p, const Vec2& q) {
  return first_crossing_over(wall, AllSegments{wall.segment_count()}, p, q);
}

std::optional<Crossing> first_crossing(const Polyline& wall, const std::vector<std::uint32_t>& segments, const Vec2& p,
                                       const Vec2& q) {
  return first_crossing_over(wall, segments, p, q);
}

std::optional<SweptCrossing> swept_crossing(const std::vector<Vec2>& before, const std::vector<Vec2>& after,
                                            const Vec2& x0, const Vec2& x1) {
  return swept_over(before, after, AllSegments{before.size() < 2 ? 0 : before.size() - 1}, x0, x1);
}

std::optional<SweptCrossing> swept_crossing(const std::vector<Vec2>& before, const std::vector<Vec2>& after,
                                            const std::vector<std::uint32_t>& segments, const Vec2& x0, const Vec2& x1) {
  return swept_over(before, after, segments, x0, x1);
}

void segments_near(const Polyline& wall, const Vec2& x, double radius, std::vector<std::uint32_t>& out) {
  out.clear();
  const double r2 = radius * radius;
  for (std::size_t k = 0; k < wall.segment_count(); ++k)
    if (closest_on_segment(wall.position[k], wall.position[k + 1], x).distance2 < r2) out.push_back(static_cast<std::uint32_t>(k));
}

}  // namespace valvefsi::fluid::thin_wall
