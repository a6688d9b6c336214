#pragma once
// The 3D thin interface as an open triangle mesh (the leaflet's mid-surface) and the geometric
// questions the two-sided wall asks of it, as polyline.hpp does in 2D: closest point and side
// (from the nearest feature's angle-weighted pseudo-normal, Baerentzen & Aanaes 2005), whether
// the closest point lies on the free boundary, whether a straight segment crosses the mesh
// (pair blocking), and whether a moving point crosses the moving mesh during a step (the
// coplanarity cubic of Provot 1997 with an in-triangle check at each root).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace valvefsi::fluid::thin_wall {

using Vec3 = std::array<double, 3>;

struct TriangleMesh {
  std::vector<Vec3> position;
  std::vector<std::array<std::uint32_t, 3>> triangles;

  // Builds the pseudo-normals and the boundary flags; call after setting or moving the nodes
  // (the connectivity is fixed). Orientation: the normal of triangle (a, b, c) is
  // (b - a) x (c - a), side +1 is the side it points to; neighbours must agree.
  void update();

  Vec3 face_normal(std::size_t t) const;  // unit
  // Pseudo-normals (not normalised): vertex = angle-weighted sum of incident face normals,
  // edge = sum of its faces' normals; edges of one triangle are the boundary.
  std::vector<Vec3> vertex_normal;
  std::vector<bool> vertex_on_boundary;
  // Per triangle, edge e joins corners e and (e + 1) % 3.
  std::vector<std::array<Vec3, 3>> edge_normal;
  std::vector<std::array<bool, 3>> edge_on_boundary;

 private:
  // Connectivity cache (built at the first update, or when the triangle count changes): for
  // every edge, the triangles and their local edge numbers that share it.
  struct Edge {
    std::uint32_t first = 0, second = 0;
    std::vector<std::pair<std::uint32_t, int>> users;
  };
  std::vector<Edge> edges_;
  std::size_t edges_for_ = static_cast<std::size_t>(-1);
};

struct ClosestPoint3 {
  std::size_t triangle = 0;
  Vec3 barycentric{};  // of the closest point in its triangle
  Vec3 point{};
  double distance = 0.0;
  int side = 1;
  // The closest point lies on a boundary edge or vertex: beyond the free edge, going from one
  // side to the other is legitimate (flow round the edge).
  bool on_boundary = false;
};

ClosestPoint3 closest_point(const TriangleMesh& mesh, const Vec3& x);
ClosestPoint3 closest_point(const TriangleMesh& mesh, const std::vector<std::uint32_t>& triangles, const Vec3& x);

// Where a straight segment p -> q meets the mesh (touching counts): the triangle and the
// parameter s along p -> q.
struct Crossing3 {
  std::size_t triangle = 0;
  double s = 0.0;
  Vec3 barycentric{};  // of the meeting point in its triangle
};
std::optional<Crossing3> first_crossing(const TriangleMesh& mesh, const Vec3& p, const Vec3& q);
// The same over a subset of triangles (candidates from a spatial search).
std::optional<Crossing3> first_crossing(const TriangleMesh& mesh, const std::vector<std::uint32_t>& triangles, const Vec3& p,
                                        const Vec3& q);
// The same for one triangle (the answer of first_crossing over {t}, without the list).
std::optional<Crossing3> crossing(const TriangleMesh& mesh, std::size_t t, const Vec3& p, const Vec3& q);

// Continuous test over a step: the point moves x0 -> x1 and the nodes before -> after, all
// linearly in tau in [0, 1]. A root of the coplanarity cubic counts when the point is inside
// the triangle then; an even number of events is no crossing. Returns the first event of an
// odd count.
struct SweptCrossing3 {
  std::size_t triangle = 0;
  double tau = 0.0;
};
std::optional<SweptCrossing3> swept_crossing(const TriangleMesh& mesh, const std::vector<Vec3>& before,
                                             const std::vector<Vec3>& after, const Vec3& x0, const Vec3& x1);
std::optional<SweptCrossing3> swept_crossing(const TriangleMesh& mesh, const std::vector<std::uint32_t>& triangles,
                                             const std::vector<Vec3>& before, const std::vector<Vec3>& after, const Vec3& x0,
                                             const Vec3& x1);

// Uniform bucket grid over the triangles' bounding boxes: the candidates of a query box are
// the triangles registered in the cells it overlaps (a superset of those that meet it).
class TriangleBuckets {
 public:
  // One box (lower, upper) per triangle; cell_size > 0.
  void build(const std::vector<std::array<Vec3, 2>>& boxes, double cell_size);
  // Triangles whose box may overlap [lower, upper], each once, ascending.
  void query(const Vec3& lower, const Vec3& upper, std::vector<std::uint32_t>& out) const;

  // Per-build cache for many boxes of at most one cell a side (a support round each particle):
  // per cell, the triangles of it and its 26 neighbours, each once, ascending, so that a query
  // is a look-up instead of a gather and sort.
  void cache_neighbourhoods();
  // A superset of query(lower, upper)'s answer, each once, ascending: the cached list of the
  // cell of the box's centre when its neighbourhood covers the box's cells (else query()'s own
  // answer, in `scratch`). Exact for callers that keep only the triangles meeting a test.
  std::span<const std::uint32_t> around(const Vec3& lower, const Vec3& upper, std::vector<std::uint32_t>& scratch) const;

 private:
  // The cells query() visits for [lower, upper] (false: none, the box is outside the grid).
  bool cell_range(const Vec3& lower, const Vec3& upper, std::array<int, 3>& l, std::array<int, 3>& u) const;
  std::size_t cell_index(int i, int j, int k) const {
    return (static_cast<std::size_t>(k) * static_cast<std::size_t>(count_[1]) + static_cast<std::size_t>(j)) *
               static_cast<std::size_t>(count_[0]) + static_cast<std::size_t>(i);
  }

  Vec3 origin_{};
  double inv_cell_ = 1.0;
  std::array<int, 3> count_{};
  std::vector<std::uint32_t> start_, items_;
  std::vector<std::uint32_t> near_start_, near_items_;  // the neighbourhoods (empty: not cached)
};

// Bounding boxes of every triangle over one or two node sets (before and after a move).
std::vector<std::array<Vec3, 2>> triangle_boxes(const TriangleMesh& mesh, const std::vector<Vec3>* other = nullptr);
// Triangles within `radius` of x among the candidates (exact point-triangle distance), the
// nearest first (queries that stop at the first hit then test the likely one first).
void triangles_within(const TriangleMesh& mesh, const std::vector<std::uint32_t>& candidates, const Vec3& x, double radius,
                      std::vector<std::uint32_t>& out);
// The same, with each found triangle's distance from x in `distances` (ascending, as `out`):
// a segment from x of length L can only meet the triangles with distance <= L.
void triangles_within(const TriangleMesh& mesh, const std::vector<std::uint32_t>& candidates, const Vec3& x, double radius,
                      std::vector<std::uint32_t>& out, std::vector<double>& distances);
// The same, skipping the candidates whose bounding box (triangle_boxes) is farther than
// `radius` (with a margin far above round-off): the same answer for less exact distances.
void triangles_within(const TriangleMesh& mesh, const std::vector<std::array<Vec3, 2>>& boxes,
                      std::span<const std::uint32_t> candidates, const Vec3& x, double radius, std::vector<std::uint32_t>& out,
                      std::vector<double>& distances);

}  // namespace valvefsi::fluid::thin_wall
