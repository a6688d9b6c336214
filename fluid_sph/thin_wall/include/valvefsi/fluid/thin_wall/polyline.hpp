#pragma once
// The 2D thin interface as an open polyline (the leaflet's mid-line) and the geometric
// questions the two-sided wall model asks of it: the closest point and the side of a point
// (from the nearest segment, not from one marker's normal), whether a straight segment
// crosses the wall (pair blocking), and whether a moving point crosses the moving wall during
// a step (continuous test in the wall's frame; both move linearly over the step).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace valvefsi::fluid::thin_wall {

using Vec2 = std::array<double, 2>;

// Node-based polyline: segment k joins node k and node k + 1. Velocities and accelerations
// are the wall's motion at the nodes (linear along each segment).
struct Polyline {
  std::vector<Vec2> position;
  std::vector<Vec2> velocity;
  std::vector<Vec2> acceleration;

  // A polyline at rest through the given nodes (at least two, consecutive nodes distinct).
  static Polyline at_rest(std::vector<Vec2> nodes);
  std::size_t node_count() const { return position.size(); }
  std::size_t segment_count() const { return position.empty() ? 0 : position.size() - 1; }
  double segment_length(std::size_t k) const;
  // Unit tangent of segment k (node k towards node k + 1) and its left normal (tangent
  // turned by +90 degrees): side +1 is the side the left normal points to.
  Vec2 tangent(std::size_t k) const;
  Vec2 normal(std::size_t k) const;
  Vec2 point(std::size_t k, double t) const;          // position at parameter t in [0, 1]
  Vec2 velocity_at(std::size_t k, double t) const;    // wall velocity there
  Vec2 acceleration_at(std::size_t k, double t) const;
};

struct ClosestPoint {
  std::size_t segment = 0;  // nearest segment
  double t = 0.0;           // parameter of the closest point on it, in [0, 1]
  Vec2 point{};             // the closest point
  double distance = 0.0;
  // +1 / -1: the side (see Polyline::normal). At an interior vertex shared by two segments
  // the side is taken from the sum of both normals (the pseudo-normal), which is exact for
  // any bend angle; for a point beyond a free end it is the side of the end segment's line.
  int side = 1;
  // The closest point is a free end node (first or last node): the point lies beyond the
  // tip, where going from one side to the other is legitimate (flow around the edge).
  bool at_free_end = false;
};

// Closest point over all segments (ties: the lower segment index).
ClosestPoint closest_point(const Polyline& wall, const Vec2& x);
// The same over a subset of segments (candidates from a spatial search).
ClosestPoint closest_point(const Polyline& wall, const std::vector<std::uint32_t>& segments, const Vec2& x);

// Where a straight segment p -> q meets the wall: the wall segment, its parameter there and
// the parameter s along p -> q. Touching counts as meeting (blocking is conservative).
struct Crossing {
  std::size_t segment = 0;
  double t = 0.0;  // along the wall segment
  double s = 0.0;  // along p -> q
};
std::optional<Crossing> first_crossing(const Polyline& wall, const Vec2& p, const Vec2& q);
std::optional<Crossing> first_crossing(const Polyline& wall, const std::vector<std::uint32_t>& segments, const Vec2& p,
                                       const Vec2& q);
inline bool crosses(const Polyline& wall, const Vec2& p, const Vec2& q) { return first_crossing(wall, p, q).has_value(); }

// Continuous crossing test over one step: the point moves x0 -> x1 and wall node k moves
// before[k] -> after[k], all linearly in the step's fraction tau in [0, 1]. The point is on
// segment k's line when cross(B - A, X - A) = 0, a quadratic in tau; a root counts when the
// point lies within the segment there. An even number of such events (out and back) is no
// crossing. Returns the first event of an odd count.
struct SweptCrossing {
  std::size_t segment = 0;
  double tau = 0.0;  // fraction of the step at which the point meets the wall
  double t = 0.0;    // parameter along the wall segment there
};
std::optional<SweptCrossing> swept_crossing(const std::vector<Vec2>& before, const std::vector<Vec2>& after,
                                            const Vec2& x0, const Vec2& x1);
std::optional<SweptCrossing> swept_crossing(const std::vector<Vec2>& before, const std::vector<Vec2>& after,
                                            const std::vector<std::uint32_t>& segments, const Vec2& x0, const Vec2& x1);

// Segments whose distance to x is below radius (the candidates for the queries above).
void segments_near(const Polyline& wall, const Vec2& x, double radius, std::vector<std::uint32_t>& out);

}  // namespace valvefsi::fluid::thin_wall
