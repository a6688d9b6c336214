#include "valvefsi/fluid/thin_wall/thin_wall_model_3d.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/fluid/equation_of_state.hpp"
#include "valvefsi/fluid/kernels.hpp"
#include "valvefsi/fluid/thin_wall/restart_arrays.hpp"

namespace valvefsi::fluid::thin_wall {
namespace {

constexpr const char* kSource = "interface surface from the coupler";

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

Vec3 position_of(const Particles<3>& p, std::size_t i) { return {p.position[0][i], p.position[1][i], p.position[2][i]}; }

int side_index(int side) { return side > 0 ? 1 : 0; }

// Cell of a point in the grid's numbering (x fastest), clamped into the grid.
std::size_t cell_of_point(const CellGrid<3>& grid, const Vec3& x) {
  std::size_t c = 0;
  for (int d = 2; d >= 0; --d) {
    int k = static_cast<int>(std::floor((x[d] - grid.lower()[d]) / grid.cell_size(d)));
    k = std::clamp(k, 0, grid.cells_along(d) - 1);
    c = c * static_cast<std::size_t>(grid.cells_along(d)) + static_cast<std::size_t>(k);
  }
  return c;
}

// Cheap rejections before the exact test: both ends strictly on one side of the triangle's
// plane, or the point where the segment meets that plane outside the triangle's box. Inlined:
// tens of millions of calls per simulated ms, most rejected by the first line.
[[gnu::always_inline]] inline bool may_meet(const std::array<Vec3, 2>& box, double sp, double sq, const Vec3& p, const Vec3& q) {
  if ((sp > 0 && sq > 0) || (sp < 0 && sq < 0)) return false;
  const double denominator = sp - sq;
  if (denominator == 0.0) return true;  // in the plane: let the exact test decide
  const double f = sp / denominator;
  const double pad = 1e-9 * (std::abs(box[1][0] - box[0][0]) + std::abs(box[1][1] - box[0][1]) + std::abs(box[1][2] - box[0][2]));
  for (int d = 0; d < 3; ++d) {
    const double x = p[d] + f * (q[d] - p[d]);
    if (x < box[0][d] - pad || x > box[1][d] + pad) return false;
  }
  return true;
}

// Signed distance of x from triangle t's plane (the cheap rejection's input; the one
// expression for it, so that a cached value is the value recomputed).
double plane_side(const std::vector<Vec3>& normal, const std::vector<double>& offset, std::uint32_t t, const Vec3& x) {
  return dot(normal[t], x) - offset[t];
}

// Whether the segment p -> q meets any of the triangles (touching counts).
bool crosses_any(const TriangleMesh& mesh, const std::vector<std::uint32_t>& triangles, const std::vector<Vec3>& normal,
                 const std::vector<double>& offset, const std::vector<std::array<Vec3, 2>>& boxes, const Vec3& p,
                 const Vec3& q) {
  for (const std::uint32_t t : triangles) {
    const double sp = plane_side(normal, offset, t, p), sq = plane_side(normal, offset, t, q);
    if (!may_meet(boxes[t], sp, sq, p, q)) continue;
    if (crossing(mesh, t, p, q)) return true;
  }
  return false;
}

// The same over candidates sorted by their distance from p (`distances`, one per triangle, or
// none: then all are tested): a triangle the segment meets lies within `reach` of p, so the scan
// stops at the first farther one. `p_sides`: p's plane_side per candidate when cached at the
// classify (or null). Exact, the answer is that of crosses_any.
bool crosses_any_within(const TriangleMesh& mesh, const std::vector<std::uint32_t>& triangles, const std::vector<double>* distances,
                        const double* p_sides, double reach, const std::vector<Vec3>& normal, const std::vector<double>& offset,
                        const std::vector<std::array<Vec3, 2>>& boxes, const Vec3& p, const Vec3& q) {
  if (distances == nullptr || distances->size() != triangles.size()) return crosses_any(mesh, triangles, normal, offset, boxes, p, q);
  for (std::size_t k = 0; k < triangles.size() && (*distances)[k] <= reach; ++k) {
    const std::uint32_t t = triangles[k];
    const double sp = p_sides != nullptr ? p_sides[k] : plane_side(normal, offset, t, p), sq = plane_side(normal, offset, t, q);
    if (!may_meet(boxes[t], sp, sq, p, q)) continue;
    if (crossing(mesh, t, p, q)) return true;
  }
  return false;
}

// One particle's candidates scattered by triangle (distance and plane side; distance +inf for
// the other triangles), per thread: the other end of a pair looks its triangles up in it.
struct ScatteredCandidates {
  const void* model = nullptr;
  std::uint64_t generation = 0;
  std::uint32_t particle = std::numeric_limits<std::uint32_t>::max();
  std::vector<double> distance, side;
  std::vector<std::uint32_t> triangles;  // the ones set, to reset

  bool holds(const void* m, std::uint64_t g, std::uint32_t i) const { return model == m && generation == g && particle == i; }
  void fill(const void* m, std::uint64_t g, std::uint32_t i, std::size_t mesh_triangles, const std::vector<std::uint32_t>& cand,
            const std::vector<double>& cand_distance, const double* cand_side) {
    if (model != m || distance.size() != mesh_triangles) {
      distance.assign(mesh_triangles, std::numeric_limits<double>::infinity());
      side.assign(mesh_triangles, 0.0);
    } else {
      for (const std::uint32_t t : triangles) distance[t] = std::numeric_limits<double>::infinity();
    }
    for (std::size_t k = 0; k < cand.size(); ++k) {
      distance[cand[k]] = cand_distance[k];
      side[cand[k]] = cand_side[k];
    }
    triangles = cand;
    model = m;
    generation = g;
    particle = i;
  }
};

// Whether the segment p -> q meets a triangle near both ends: the candidates of one end (`list`,
// distances ascending, its plane sides; it is p when list_is_p) up to list_reach, each looked up
// in the other end's scatter and kept only within other_reach of it and with the two distances'
// sum within `bound` (a triangle met at m is within |pm| of p and |mq| of q). The same plane test
// and exact test on the same values as crosses_any_within decide those kept.
bool crosses_common(const TriangleMesh& mesh, const std::vector<std::array<Vec3, 2>>& boxes, const std::vector<std::uint32_t>& list,
                    const std::vector<double>& dist, const double* sides, double list_reach, bool list_is_p,
                    const ScatteredCandidates& other, double other_reach, double bound, const Vec3& p, const Vec3& q) {
  for (std::size_t k = 0; k < list.size() && dist[k] <= list_reach; ++k) {
    const std::uint32_t t = list[k];
    const double d = other.distance[t];
    if (d > other_reach || dist[k] + d > bound) continue;
    const double sp = list_is_p ? sides[k] : other.side[t], sq = list_is_p ? other.side[t] : sides[k];
    if (!may_meet(boxes[t], sp, sq, p, q)) continue;
    if (crossing(mesh, t, p, q)) return true;
  }
  return false;
}

// A candidate triangle as one particle's lattice behind one sheet sees it (add_surface_rates):
// its corners in the lattice's frame (t1, t2, n) from the particle, and per layer the rectangle
// of lattice offsets (i delta, j delta) whose segment from the particle can meet it.
struct ShadowBound {
  enum Kind : std::uint8_t { test, never, rectangle };
  Kind kind = test;
  std::array<double, 3> xi{}, eta{}, zeta{};
  double spread = 1.0;                        // the corners' largest |zeta| over their smallest
  double lo1 = 0, hi1 = 0, lo2 = 0, hi2 = 0;  // the current layer's rectangle

  // Whether the segment to the layer's point at offsets (i delta, j delta) certainly misses.
  bool misses(double offset1, double offset2) const {
    return kind == never || (kind == rectangle && (offset1 < lo1 || offset1 > hi1 || offset2 < lo2 || offset2 > hi2));
  }
};

// The per-sheet and per-layer set-up of the ShadowBounds (see add_surface_rates). Out of line:
// the lattice's own arithmetic around the call is then compiled as before (the build contracts
// a * b + c into FMAs where it sees fit, so code inlined beside it could change its last bits).
[[gnu::noinline]] void frame_shadow_bounds(const TriangleMesh& mesh, const std::vector<std::uint32_t>& cand, const Vec3& xa,
                                           const Vec3& t1, const Vec3& t2, const Vec3& n, double zeta_margin, double front,
                                           std::vector<ShadowBound>& bounds) {
  bounds.resize(cand.size());
  for (std::size_t k = 0; k < cand.size(); ++k) {
    ShadowBound& b = bounds[k];
    b.kind = ShadowBound::test;
    const auto& tri = mesh.triangles[cand[k]];
    double zmin = std::numeric_limits<double>::infinity(), zmax = -zmin;
    for (std::size_t m = 0; m < 3; ++m) {
      const Vec3 w = sub(mesh.position[tri[m]], xa);
      b.xi[m] = dot(w, t1);
      b.eta[m] = dot(w, t2);
      b.zeta[m] = dot(w, n);
      zmin = std::min(zmin, b.zeta[m]);
      zmax = std::max(zmax, b.zeta[m]);
    }
    if (zmin >= zeta_margin) {
      b.kind = ShadowBound::never;
    } else if (zmax <= -front) {  // well in front: the projection stays bounded
      b.kind = ShadowBound::rectangle;
      b.spread = zmin / zmax;
    }
  }
}

[[gnu::noinline]] void layer_shadow_bounds(double level, double o1, double o2, double delta, std::vector<ShadowBound>& bounds) {
  for (auto& b : bounds) {
    if (b.kind != ShadowBound::rectangle) continue;
    b.lo1 = b.lo2 = std::numeric_limits<double>::infinity();
    b.hi1 = b.hi2 = -b.lo1;
    double extent = 0.0;
    for (std::size_t m = 0; m < 3; ++m) {
      const double scale = level / b.zeta[m];
      const double u = b.xi[m] * scale, v = b.eta[m] * scale;
      extent = std::max({extent, std::abs(u), std::abs(v)});
      b.lo1 = std::min(b.lo1, u - o1);
      b.hi1 = std::max(b.hi1, u - o1);
      b.lo2 = std::min(b.lo2, v - o2);
      b.hi2 = std::max(b.hi2, v - o2);
    }
    const double margin = 1e-6 * delta + 1e-8 * b.spread * extent;
    b.lo1 -= margin;
    b.hi1 += margin;
    b.lo2 -= margin;
    b.hi2 += margin;
  }
}

// The frame's offsets of the closest point from the particle (o1, o2, o3), out of line as above.
[[gnu::noinline]] std::array<double, 3> frame_offsets(const Vec3& point, const Vec3& xa, const Vec3& t1, const Vec3& t2, const Vec3& n) {
  const Vec3 to_point = sub(point, xa);
  return {dot(to_point, t1), dot(to_point, t2), dot(to_point, n)};
}

// Fresh for every classify (of any model): tells the per-thread caches that they are stale.
std::uint64_t next_generation() {
  static std::atomic<std::uint64_t> counter{0};
  return ++counter;
}

// Length of the shortest path from a to b through a point of the segment [p, q]. The sum of the
// two distances is convex along the segment, so a golden-section search finds its minimum
// (to 1e-6 of the segment, far below dp for the path's use: reachable round a free edge).
double path_through_segment(const Vec3& a, const Vec3& b, const Vec3& p, const Vec3& q) {
  const Vec3 e = sub(q, p);
  auto length = [&](double t) {
    const Vec3 x{p[0] + t * e[0], p[1] + t * e[1], p[2] + t * e[2]};
    return norm(sub(a, x)) + norm(sub(b, x));
  };
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double lo = 0.0, hi = 1.0;
  double t1 = hi - g * (hi - lo), t2 = lo + g * (hi - lo);
  double f1 = length(t1), f2 = length(t2);
  while (hi - lo > 1e-6) {
    if (f1 <= f2) {
      hi = t2;
      t2 = t1;
      f2 = f1;
      t1 = hi - g * (hi - lo);
      f1 = length(t1);
    } else {
      lo = t1;
      t1 = t2;
      f1 = f2;
      t2 = lo + g * (hi - lo);
      f2 = length(t2);
    }
  }
  return std::min({f1, f2, length(0.0), length(1.0)});
}

// Distance from x to the segment [p, q].
double distance_to_segment(const Vec3& x, const Vec3& p, const Vec3& q) {
  const Vec3 e = sub(q, p), d = sub(x, p);
  const double ee = dot(e, e);
  const double t = ee > 0 ? std::clamp(dot(d, e) / ee, 0.0, 1.0) : 0.0;
  return norm(sub(d, {t * e[0], t * e[1], t * e[2]}));
}

}  // namespace

std::size_t orient_consistently(std::vector<std::array<std::uint32_t, 3>>& triangles) {
  // Edge -> (triangle, direction +1 if it runs low -> high node).
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::pair<std::size_t, int>>> edges;
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t i = triangles[t][static_cast<std::size_t>(k)], j = triangles[t][static_cast<std::size_t>((k + 1) % 3)];
      auto& users = edges[{std::min(i, j), std::max(i, j)}];
      users.push_back({t, i < j ? 1 : -1});
      if (users.size() > 2)
        throw std::invalid_argument(fmt::format("{}: the edge between nodes {} and {} is shared by more than two triangles ({}, {}, "
                                                "{}): a leaflet is a surface with no branches",
                                                kSource, std::min(i, j), std::max(i, j), users[0].first, users[1].first, t));
    }
  std::vector<std::vector<std::pair<std::size_t, bool>>> neighbours(triangles.size());  // (other, same direction)
  for (const auto& [key, users] : edges)
    if (users.size() == 2) {
      const bool same = users[0].second == users[1].second;
      neighbours[users[0].first].push_back({users[1].first, same});
      neighbours[users[1].first].push_back({users[0].first, same});
    }
  std::vector<int> flip(triangles.size(), -1);  // -1 unvisited, 0 keep, 1 flip
  std::size_t flipped = 0;
  for (std::size_t seed = 0; seed < triangles.size(); ++seed) {
    if (flip[seed] >= 0) continue;
    flip[seed] = 0;
    std::vector<std::size_t> stack{seed};
    while (!stack.empty()) {
      const std::size_t t = stack.back();
      stack.pop_back();
      for (const auto& [o, same] : neighbours[t]) {
        // Consistent neighbours traverse the shared edge in opposite directions.
        const int want = same ? 1 - flip[t] : flip[t];
        if (flip[o] < 0) {
          flip[o] = want;
          stack.push_back(o);
        } else if (flip[o] != want) {
          throw std::invalid_argument(fmt::format("{}: triangles {} and {} cannot be oriented consistently (a non-orientable "
                                                  "surface): the two sides of a leaflet must be distinct",
                                                  kSource, t, o));
        }
      }
    }
  }
  for (std::size_t t = 0; t < triangles.size(); ++t)
    if (flip[t] == 1) {
      std::swap(triangles[t][1], triangles[t][2]);
      ++flipped;
    }
  return flipped;
}

ThinWallModel3D::ThinWallModel3D(const ImmersedSurfaceGeometry<3>& g, const FluidSettings<3>& fluid, ThinWall3DSettings settings)
    : fluid_(fluid), settings_(settings), node_count_(g.nodes.size()), planes_(fluid.mirror_planes),
      dyn_(WindowMotionT<3>(std::vector<Vec3>(g.nodes.begin(), g.nodes.end()), 0.0)) {
  if (g.nodes_per_cell != 3)
    throw std::invalid_argument(fmt::format("{}: nodes_per_cell = {}: allowed 3 (triangles) in 3D", kSource, g.nodes_per_cell));
  if (g.cells.empty() || g.cells.size() % 3 != 0)
    throw std::invalid_argument(fmt::format("{}: cells has {} entries: allowed 3 per triangle, at least one triangle", kSource,
                                            g.cells.size()));
  if (g.node_thickness.size() != node_count_)
    throw std::invalid_argument(fmt::format("{}: node_thickness has {} entries: allowed one per node ({})", kSource,
                                            g.node_thickness.size(), node_count_));
  const double dp = fluid.particle_spacing;
  double thickest = 0.0;
  for (std::size_t k = 0; k < node_count_; ++k) {
    if (!(g.node_thickness[k] >= 0.0) || !(g.node_thickness[k] < dp))
      throw std::invalid_argument(fmt::format("{}: node_thickness[{}] = {} m: allowed 0 <= t < the particle spacing {} m", kSource,
                                              k, g.node_thickness[k], dp));
    thickest = std::max(thickest, g.node_thickness[k]);
  }
  if (!(settings_.virtual_spacing_ratio > 0))
    throw std::invalid_argument(fmt::format("thin wall 3D: virtual_spacing_ratio = {}: allowed > 0", settings_.virtual_spacing_ratio));
  std::vector<std::array<std::uint32_t, 3>> triangles(g.cells.size() / 3);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t n = g.cells[3 * t + static_cast<std::size_t>(k)];
      if (n >= node_count_)
        throw std::invalid_argument(fmt::format("{}: triangle {} names node {}: allowed 0 to {}", kSource, t, n, node_count_ - 1));
      triangles[t][static_cast<std::size_t>(k)] = n;
    }
    const auto& tri = triangles[t];
    const Vec3 n = cross(sub(g.nodes[tri[1]], g.nodes[tri[0]]), sub(g.nodes[tri[2]], g.nodes[tri[0]]));
    if (!(norm(n) > 1e-12 * dp * dp))
      throw std::invalid_argument(
          fmt::format("{}: triangle {} (nodes {}, {}, {}) has no area: allowed non-degenerate triangles", kSource, t, tri[0], tri[1], tri[2]));
  }
  orient_consistently(triangles);
  real_triangles_ = triangles.size();
  area_.assign(node_count_, 0.0);
  for (const auto& tri : triangles) {
    const double a = 0.5 * norm(cross(sub(g.nodes[tri[1]], g.nodes[tri[0]]), sub(g.nodes[tri[2]], g.nodes[tri[0]])));
    for (const std::uint32_t n : tri) area_[n] += a / 3.0;
  }
  clearance_ = std::max(settings_.clearance_ratio * dp, 0.5 * thickest);
  if (settings_.load_smoothing_radius_ratio > 0.0)
    smoother_ = NodeLoadSmoother(g.nodes, triangles, area_, settings_.load_smoothing_radius_ratio * dp);

  // The mesh with its mirror images, under each plane's reflection and, where the planes cross
  // (a sector's axis), every other element of the group they generate, as the fluid makes its
  // images of images. An image node that falls on an existing node of the same real node (a
  // node on a plane is its own image there) is that node, so the leaflet and its image share
  // the edge along the symmetry line (an interior edge, not a free one).
  for (const auto& plane : planes_) {
    MirrorMap<3> m;
    const double pn = dot(plane.point, plane.normal);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) m.matrix[r][c] = (r == c ? 1.0 : 0.0) - 2.0 * plane.normal[r] * plane.normal[c];
      m.shift[r] = 2.0 * pn * plane.normal[r];
    }
    maps_.push_back(m);
  }
  if (fluid.mirror_images_of_images && planes_.size() > 1)
    for (const auto& m : compound_mirror_maps<3>(planes_)) maps_.push_back(m);
  mesh_.triangles = triangles;
  origin_node_.resize(node_count_);
  for (std::uint32_t k = 0; k < node_count_; ++k) origin_node_[k] = k;
  node_map_.assign(node_count_, -1);
  triangle_map_.assign(real_triangles_, -1);
  std::vector<std::vector<std::uint32_t>> copies(node_count_);  // mesh nodes per real node
  std::vector<Vec3> placed(g.nodes.begin(), g.nodes.end());
  for (std::uint32_t k = 0; k < node_count_; ++k) copies[k].push_back(k);
  std::set<std::array<std::uint32_t, 3>> known;
  for (const auto& tri : triangles) {
    auto key = tri;
    std::sort(key.begin(), key.end());
    known.insert(key);
  }
  for (std::size_t m = 0; m < maps_.size(); ++m) {
    std::vector<std::uint32_t> image(node_count_);
    for (std::uint32_t k = 0; k < node_count_; ++k) {
      const Vec3 y = maps_[m].apply(g.nodes[k]);
      image[k] = static_cast<std::uint32_t>(origin_node_.size());
      for (const std::uint32_t c : copies[k])
        if (norm(sub(placed[c], y)) < 1e-3 * dp) image[k] = c;
      if (image[k] == origin_node_.size()) {
        origin_node_.push_back(k);
        node_map_.push_back(static_cast<int>(m));
        placed.push_back(y);
        copies[k].push_back(image[k]);
      }
    }
    const auto& a = maps_[m].matrix;
    const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                       a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    for (std::size_t t = 0; t < real_triangles_; ++t) {
      const auto& tri = triangles[t];
      // A reflection turns the orientation over: swap two corners to keep the sides.
      const std::array<std::uint32_t, 3> mapped = det < 0 ? std::array<std::uint32_t, 3>{image[tri[0]], image[tri[2]], image[tri[1]]}
                                                          : std::array<std::uint32_t, 3>{image[tri[0]], image[tri[1]], image[tri[2]]};
      auto key = mapped;
      std::sort(key.begin(), key.end());
      if (!known.insert(key).second) continue;  // the triangle is its own image (in a plane)
      mesh_.triangles.push_back(mapped);
      triangle_map_.push_back(static_cast<int>(m));
    }
  }
  mesh_.position.resize(origin_node_.size());
  // Sheets: the connected pieces of the mesh (triangles sharing a node), found once.
  std::vector<std::uint32_t> parent(origin_node_.size());
  for (std::uint32_t k = 0; k < parent.size(); ++k) parent[k] = k;
  auto root = [&](std::uint32_t k) {
    while (parent[k] != k) k = parent[k] = parent[parent[k]];
    return k;
  };
  for (const auto& tri : mesh_.triangles) {
    parent[root(tri[1])] = root(tri[0]);
    parent[root(tri[2])] = root(tri[0]);
  }
  sheet_of_triangle_.resize(mesh_.triangles.size());
  for (std::size_t t = 0; t < mesh_.triangles.size(); ++t) sheet_of_triangle_[t] = static_cast<int>(root(mesh_.triangles[t][0]));
  move_to(0.0);
}

Vec3 ThinWallModel3D::to_image(int map, const Vec3& v) const {
  if (map < 0) return v;
  return maps_[static_cast<std::size_t>(map)].rotate(v);
}

Vec3 ThinWallModel3D::to_real(int map, const Vec3& v) const {
  if (map < 0) return v;
  const auto& a = maps_[static_cast<std::size_t>(map)].matrix;  // orthogonal: the inverse is the transpose
  return {a[0][0] * v[0] + a[1][0] * v[1] + a[2][0] * v[2], a[0][1] * v[0] + a[1][1] * v[1] + a[2][1] * v[2],
          a[0][2] * v[0] + a[1][2] * v[1] + a[2][2] * v[2]};
}

void ThinWallModel3D::place_mesh() {
  const std::size_t n = origin_node_.size();
  mesh_velocity_.resize(n);
  mesh_acceleration_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t j = origin_node_[k];
    const int map = node_map_[k];
    mesh_.position[k] = map < 0 ? dyn_.x[j] : maps_[static_cast<std::size_t>(map)].apply(dyn_.x[j]);
    mesh_velocity_[k] = to_image(map, dyn_.v[j]);
    mesh_acceleration_[k] = to_image(map, dyn_.a[j]);
  }
  mesh_.update();
  buckets_current_ = false;  // until the next classify
  face_normal_.resize(mesh_.triangles.size());
  face_offset_.resize(mesh_.triangles.size());
  face_box_ = triangle_boxes(mesh_);
  for (std::size_t t = 0; t < mesh_.triangles.size(); ++t) {
    face_normal_[t] = mesh_.face_normal(t);
    face_offset_[t] = dot(face_normal_[t], mesh_.position[mesh_.triangles[t][0]]);
  }
}

void ThinWallModel3D::set_window_target(double end_time, std::span<const Vec<3>> end_positions,
                                        std::span<const Vec<3>> end_velocities) {
  dyn_.motion.set_target(end_time, end_positions, end_velocities);
}

void ThinWallModel3D::move_to(double time) {
  dyn_.motion.evaluate(time, dyn_.x, dyn_.v, dyn_.a);
  place_mesh();
}

double ThinWallModel3D::max_node_speed() const {
  double v2 = 0.0;
  for (const auto& v : dyn_.v) v2 = std::max(v2, dot(v, v));
  return std::max(std::sqrt(v2), dyn_.motion.max_end_speed());
}

void ThinWallModel3D::begin_step(const Particles<3>& p) {
  auto& s = dyn_;
  s.start_position.resize(p.size());
  std::uint32_t max_id = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    s.start_position[i] = position_of(p, i);
    max_id = std::max(max_id, p.id[i]);
  }
  s.start_nodes = mesh_.position;
  s.previous_by_id.resize(static_cast<std::size_t>(max_id) + 1);
  for (std::size_t i = 0; i < p.size(); ++i) s.previous_by_id[p.id[i]] = s.start_position[i];
  std::fill(s.corrected_by_id.begin(), s.corrected_by_id.end(), std::uint8_t{0});
}

void ThinWallModel3D::correct_crossings(Particles<3>& p) {
  auto& s = dyn_;
  if (s.start_nodes.size() != mesh_.position.size() || s.start_position.size() != p.size()) return;  // no begin_step yet
  const double R = fluid_.support_radius();
  TriangleBuckets swept;
  swept.build(triangle_boxes(mesh_, &s.start_nodes), R);
  Vec3 lo = mesh_.position[0], hi = mesh_.position[0];
  for (const auto* nodes : {&s.start_nodes, &mesh_.position})
    for (const auto& x : *nodes)
      for (int d = 0; d < 3; ++d) {
        lo[d] = std::min(lo[d], x[d]);
        hi[d] = std::max(hi[d], x[d]);
      }
  std::size_t corrections = 0;
  const auto count = static_cast<std::ptrdiff_t>(p.size());
#pragma omp parallel reduction(+ : corrections)
  {
    std::vector<std::uint32_t> candidates, one(1);
#pragma omp for schedule(dynamic, 256)
    for (std::ptrdiff_t ii = 0; ii < count; ++ii) {
      const auto i = static_cast<std::size_t>(ii);
      if (p.kind[i] != Kind::fluid) continue;
      const Vec3 x0 = s.start_position[i];
      const Vec3 x1 = position_of(p, i);
      bool outside = false;
      for (int d = 0; d < 3; ++d) outside = outside || std::min(x0[d], x1[d]) > hi[d] || std::max(x0[d], x1[d]) < lo[d];
      if (outside) continue;
      swept.query({std::min(x0[0], x1[0]), std::min(x0[1], x1[1]), std::min(x0[2], x1[2])},
                  {std::max(x0[0], x1[0]), std::max(x0[1], x1[1]), std::max(x0[2], x1[2])}, candidates);
      if (candidates.empty()) continue;
      const auto hit = swept_crossing(mesh_, candidates, s.start_nodes, mesh_.position, x0, x1);
      if (!hit) continue;
      const std::size_t t = hit->triangle;
      const auto& tri = mesh_.triangles[t];
      // Side at the start of the step, from the triangle that was crossed.
      const Vec3 n0 = cross(sub(s.start_nodes[tri[1]], s.start_nodes[tri[0]]), sub(s.start_nodes[tri[2]], s.start_nodes[tri[0]]));
      const double side = dot(sub(x0, s.start_nodes[tri[0]]), n0) >= 0.0 ? 1.0 : -1.0;
      const Vec3 n{side * face_normal_[t][0], side * face_normal_[t][1], side * face_normal_[t][2]};
      const double signed_distance = dot(sub(x1, mesh_.position[tri[0]]), n);
      const double depth = std::max(-signed_distance, 0.0);
      const double move = depth + std::max(depth, clearance_);
      for (int d = 0; d < 3; ++d) p.position[d][i] = x1[d] + move * n[d];
      // Reflect the velocity relative to the wall, normal part only, if it points into the wall.
      one[0] = static_cast<std::uint32_t>(t);
      const ClosestPoint3 c = closest_point(mesh_, one, x1);
      Vec3 vw{0, 0, 0};
      for (int k = 0; k < 3; ++k)
        for (int d = 0; d < 3; ++d) vw[d] += c.barycentric[static_cast<std::size_t>(k)] * mesh_velocity_[tri[static_cast<std::size_t>(k)]][d];
      double vn = 0;
      for (int d = 0; d < 3; ++d) vn += (p.velocity[d][i] - vw[d]) * n[d];
      if (vn < 0.0)
        for (int d = 0; d < 3; ++d) {
          p.velocity[d][i] = static_cast<float>(p.velocity[d][i] - 2.0 * vn * n[d]);
          p.viscous_velocity[d][i] = p.velocity[d][i];
        }
      if (p.id[i] < s.corrected_by_id.size()) s.corrected_by_id[p.id[i]] = 1;
      ++corrections;
    }
  }
  s.counters.corrections += corrections;
}

void ThinWallModel3D::classify(const Particles<3>& p) {
  auto& s = dyn_;
  const std::size_t n = p.size();
  s.near.assign(n, NearWall{});
  s.candidates.resize(n);
  s.candidate_distance.resize(n);
  std::uint32_t max_id = 0;
  for (std::size_t i = 0; i < n; ++i) max_id = std::max(max_id, p.id[i]);
  if (s.side_by_id.size() <= max_id) s.side_by_id.resize(max_id + 1, 0);
  if (s.corrected_by_id.size() <= max_id) s.corrected_by_id.resize(max_id + 1, 0);
  const double R = fluid_.support_radius();
  s.candidate_side.resize(n);
  s.classified_position.resize(n);
  buckets_.build(face_box_, R);
  buckets_.cache_neighbourhoods();  // one gather and sort per cell, not per particle
  buckets_current_ = true;
  generation_ = next_generation();
  Vec3 lo = mesh_.position[0], hi = mesh_.position[0];
  for (const auto& x : mesh_.position)
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], x[d] - R);
      hi[d] = std::max(hi[d], x[d] + R);
    }
  std::size_t leaks = 0;
  const auto count = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel reduction(+ : leaks)
  {
    std::vector<std::uint32_t> boxed, nearest(1);
#pragma omp for schedule(dynamic, 256)
    for (std::ptrdiff_t ii = 0; ii < count; ++ii) {
      const auto i = static_cast<std::size_t>(ii);
      auto& cand = s.candidates[i];
      auto& cand_distance = s.candidate_distance[i];
      auto& cand_side = s.candidate_side[i];
      cand.clear();
      cand_distance.clear();
      cand_side.clear();
      const Vec3 x = position_of(p, i);
      s.classified_position[i] = x;
      if (p.kind[i] == Kind::lost) continue;
      const std::uint32_t id = p.id[i];
      bool outside = false;
      for (int d = 0; d < 3; ++d) outside = outside || x[d] < lo[d] || x[d] > hi[d];
      if (!outside) {
        // A superset of the buckets' answer for the support round x: the same triangles within R.
        const auto around = buckets_.around({x[0] - R, x[1] - R, x[2] - R}, {x[0] + R, x[1] + R, x[2] + R}, boxed);
        triangles_within(mesh_, face_box_, around, x, R, cand, cand_distance);
        cand_side.resize(cand.size());
        for (std::size_t k = 0; k < cand.size(); ++k) cand_side[k] = plane_side(face_normal_, face_offset_, cand[k], x);
      }
      if (cand.empty()) {
        if (p.kind[i] == Kind::fluid) s.side_by_id[id] = 0;
        continue;
      }
      NearWall& nw = s.near[i];
      // The candidates come nearest first, by the distance closest_point computes (ties by
      // index): the first is its answer, without the other candidates' distances again.
      nearest[0] = cand[0];
      nw.closest = closest_point(mesh_, nearest, x);
      nw.near = true;
      if (p.kind[i] != Kind::fluid) continue;
      // A particle may change side only round a free edge or through a put-back; otherwise
      // it leaked (entering the near zone from outside cannot be a crossing). A straight step
      // that misses the mesh went round the edge.
      auto& remembered = s.side_by_id[id];
      const auto side = static_cast<std::int8_t>(nw.closest.side);
      if (remembered != 0 && remembered != side && !nw.closest.on_boundary && !s.corrected_by_id[id] &&
          (id >= s.previous_by_id.size() || crosses_any(mesh_, cand, face_normal_, face_offset_, face_box_, s.previous_by_id[id], x)))
        ++leaks;
      remembered = side;
    }
  }
  s.counters.leaks += leaks;
}

bool ThinWallModel3D::blocked(std::uint32_t a, std::uint32_t b, const Particles<3>& p) const {
  const auto& near = dyn_.near;
  if (!near[a].near || !near[b].near) return false;
  const Vec3 xa = position_of(p, a), xb = position_of(p, b);
  const double ab = norm(sub(xb, xa));
  // Beyond the support the pair has no weight (the solver may ask before its distance cut);
  // and the distance to the mesh changes by at most the distance moved, so a segment shorter
  // than the sum of its ends' distances cannot reach the mesh.
  const double R = fluid_.support_radius();
  if (ab >= R || ab < near[a].closest.distance + near[b].closest.distance) return false;
  // A triangle met at m is within |am| of a while b is at least its distance d_b from the mesh
  // away from m: only a's candidates within |ab| - d_b can be met (the margin covers rounding).
  const double reach = ab - near[b].closest.distance + reach_margin();
  const double* sides_a = sides_of(a, xa);
  const double* sides_b = sides_of(b, xb);
  if (sides_a == nullptr || sides_b == nullptr || distances_of(a) == nullptr || distances_of(b) == nullptr || !(ab < R - reach_margin()))
    return crosses_any_within(mesh_, dyn_.candidates[a], distances_of(a), sides_a, reach, face_normal_, face_offset_, face_box_, xa, xb);
  // Closer still: a triangle met at m is within |am| of a and |mb| of b, so (|ab| < R) it is a
  // candidate of both with d_a + d_b <= |ab|, a thin ellipsoid round the segment. With one
  // end's candidates scattered by triangle, the other end's list drops the rest by a look-up.
  // The same plane test and exact test on the same values decide the few left: the answer of
  // crosses_any_within (these triangles are a subset of its own, the rest cannot be met).
  const double bound = ab + 2.0 * reach_margin();
  thread_local std::array<ScatteredCandidates, 2> slots;
  thread_local std::uint32_t last_b = std::numeric_limits<std::uint32_t>::max();
  thread_local int next_slot = 0;
  const ScatteredCandidates* of_a = nullptr;
  const ScatteredCandidates* of_b = nullptr;
  for (const auto& slot : slots) {
    if (slot.holds(this, generation_, a)) of_a = &slot;
    if (slot.holds(this, generation_, b)) of_b = &slot;
  }
  if (of_a == nullptr && of_b == nullptr) {
    // Scatter the end that repeats: b when the caller sweeps many a against one b, else a.
    const std::uint32_t i = b == last_b ? b : a;
    ScatteredCandidates& slot = slots[static_cast<std::size_t>(next_slot)];
    next_slot = 1 - next_slot;
    slot.fill(this, generation_, i, mesh_.triangles.size(), dyn_.candidates[i], dyn_.candidate_distance[i], i == a ? sides_a : sides_b);
    (i == a ? of_a : of_b) = &slot;
  }
  last_b = b;
  const double inf = std::numeric_limits<double>::infinity();
  if (of_a != nullptr)  // b's list (within bound - d_a of b, as d_a <= D_a), a's look-ups
    return crosses_common(mesh_, face_box_, dyn_.candidates[b], dyn_.candidate_distance[b], sides_b, bound - near[a].closest.distance,
                          false, *of_a, reach, bound, xa, xb);
  return crosses_common(mesh_, face_box_, dyn_.candidates[a], dyn_.candidate_distance[a], sides_a, reach, true, *of_b, inf, bound, xa,
                        xb);
}

void ThinWallModel3D::update_surface_states(const Particles<3>& p, const CellGrid<3>& grid) {
  auto& s = dyn_;
  const double R = fluid_.support_radius();
  const double tiny = 1e-6 * fluid_.particle_spacing;
  s.state.resize(node_count_);
  const auto count = static_cast<std::ptrdiff_t>(node_count_);
  with_kernel<3>(fluid_.kernel, fluid_.smoothing_length(), [&](const auto& W) {
#pragma omp parallel for schedule(dynamic, 4)
    for (std::ptrdiff_t jj = 0; jj < count; ++jj) {
      const auto j = static_cast<std::size_t>(jj);
      const Vec3 xm = mesh_.position[j];
      Vec3 nm = mesh_.vertex_normal[j];
      const double nl = norm(nm);
      nm = {nm[0] / nl, nm[1] / nl, nm[2] / nl};
      const Vec3 am = settings_.wall_acceleration_in_pressure ? dyn_.a[j] : Vec3{0, 0, 0};
      // The triangles near the node seen from each side, scattered once for all its particles
      // (as the blocking's per-particle scatter: a triangle between b and the node is near both).
      thread_local std::array<ScatteredCandidates, 2> seen_from;
      thread_local std::vector<std::uint32_t> near_node, boxed;
      thread_local std::vector<double> near_node_distance, near_node_side;
      std::array<bool, 2> scattered{false, false};
      std::array<NeighbourSegment<3>, 27> segments;
      const int segment_count = grid.neighbour_segments(cell_of_point(grid, xm), segments);
      double sw[2] = {0, 0}, sp[2] = {0, 0}, srr[2][3] = {}, sv[2][3] = {};
      for (int g = 0; g < segment_count; ++g) {
        const auto& seg = segments[static_cast<std::size_t>(g)];
        for (std::uint32_t b = seg.begin; b < seg.end; ++b) {
          if (!acts_as_fluid(p.kind[b]) || !s.near[b].near) continue;
          const Vec3 xb{p.position[0][b] + seg.shift[0], p.position[1][b] + seg.shift[1], p.position[2][b] + seg.shift[2]};
          const Vec3 r = sub(xm, xb);
          const double dist = norm(r);
          if (dist >= R) continue;
          const int side = s.near[b].closest.side;
          // The node as seen from b's side: nothing of the mesh may lie in between.
          const Vec3 target{xm[0] + side * tiny * nm[0], xm[1] + side * tiny * nm[1], xm[2] + side * tiny * nm[2]};
          const bool shifted = seg.shift[0] != 0 || seg.shift[1] != 0 || seg.shift[2] != 0;  // candidates are b's own
          const double to_target = norm(sub(target, xb));
          const double reach = shifted ? std::numeric_limits<double>::infinity() : to_target + reach_margin();
          const double* sides_b = shifted ? nullptr : sides_of(b, xb);
          const int k_seen = side_index(side);
          if (sides_b != nullptr && distances_of(b) != nullptr && buckets_current_ && to_target < R - reach_margin()) {
            ScatteredCandidates& seen = seen_from[static_cast<std::size_t>(k_seen)];
            if (!scattered[static_cast<std::size_t>(k_seen)]) {
              const Vec3 lower{target[0] - R, target[1] - R, target[2] - R}, upper{target[0] + R, target[1] + R, target[2] + R};
              const auto around = buckets_.around(lower, upper, boxed);
              triangles_within(mesh_, face_box_, around, target, R, near_node, near_node_distance);
              near_node_side.resize(near_node.size());
              for (std::size_t k = 0; k < near_node.size(); ++k)
                near_node_side[k] = plane_side(face_normal_, face_offset_, near_node[k], target);
              seen.fill(this, 0, static_cast<std::uint32_t>(j), mesh_.triangles.size(), near_node, near_node_distance,
                        near_node_side.data());
              scattered[static_cast<std::size_t>(k_seen)] = true;
            }
            if (crosses_common(mesh_, face_box_, s.candidates[b], s.candidate_distance[b], sides_b, reach, true, seen,
                               std::numeric_limits<double>::infinity(), to_target + 2.0 * reach_margin(), xb, target))
              continue;
          } else if (crosses_any_within(mesh_, s.candidates[b], distances_of(b), sides_of(b, xb), reach, face_normal_, face_offset_,
                                        face_box_, xb, target)) {
            continue;
          }
          const double w = W.value(static_cast<float>(dist));
          const int k = side_index(side);
          const double rho_b = fluid_.rest_density + p.density_excess[b];
          sw[k] += w;
          sp[k] += p.pressure[b] * w;
          for (int d = 0; d < 3; ++d) {
            srr[k][d] += rho_b * r[d] * w;
            sv[k][d] += p.velocity[d][b] * w;
          }
        }
      }
      for (int k = 0; k < 2; ++k) {
        SideState& st = s.state[j].side[static_cast<std::size_t>(k)];
        st.weight = sw[k];
        if (sw[k] > 0) {
          // Adami, Hu & Adams 2012, eq. 27, with the wall's acceleration (if enabled).
          double pw = sp[k];
          for (int d = 0; d < 3; ++d) pw += (fluid_.gravity[d] - am[d]) * srr[k][d];
          st.pressure = pw / sw[k];
          st.velocity = {sv[k][0] / sw[k], sv[k][1] / sw[k], sv[k][2] / sw[k]};
        } else {
          st.pressure = fluid_.background_pressure;
          st.velocity = dyn_.v[j];
        }
      }
    }
  });
}

void ThinWallModel3D::add_surface_rates(Particles<3>& p) {
  auto& s = dyn_;
  const double dp = fluid_.particle_spacing;
  const double R = fluid_.support_radius();
  const double delta = settings_.virtual_spacing_ratio * dp;
  const int layers = static_cast<int>(std::ceil(R / delta));
  const double rho0 = fluid_.rest_density;
  const double mass_a = fluid_.particle_mass();
  const double mass_v = rho0 * delta * delta * delta;
  const double two_mu = 2.0 * fluid_.dynamic_viscosity;
  const double alpha_c0 = fluid_.artificial_viscosity * fluid_.sound_speed;
  const double h = fluid_.smoothing_length();
  const double eta2 = 0.01 * h * h;
  const LinearMieGruneisen eos{rho0, fluid_.sound_speed};
  const bool with_kernel_sum = p.kernel_sum.size() == p.size();
  if (s.state.size() != node_count_) s.state.assign(node_count_, NodeState{});

  node_loads_.reset(node_count_, p.size());
  const auto blocks = static_cast<std::ptrdiff_t>(node_loads_.block_count());
  with_kernel<3>(fluid_.kernel, h, [&](const auto& W) {
#pragma omp parallel
    {
      OrderedNodeLoads<3>::Booking forces(node_loads_);
      std::vector<double>
          side_scratch;  // signed distance of the particle from each candidate's plane
      std::vector<ClosestPoint3> sheets;
      std::vector<std::uint32_t> one;  // one sheet's candidates
      std::vector<std::array<Vec3, 2>> free_edges;
      std::vector<ShadowBound> bounds;  // per candidate, for the current sheet and layer
      // The node loads are booked per block of particles and summed in block order
      // (OrderedNodeLoads): the same in every run, on any number of threads.
#pragma omp for schedule(dynamic, 4)
      for (std::ptrdiff_t block = 0; block < blocks; ++block) {
        const auto [first, last] = node_loads_.block_range(static_cast<std::size_t>(block));
        for (std::size_t a = first; a < last; ++a) {
          if (p.kind[a] != Kind::fluid || !s.near[a].near) continue;
          const auto& cand = s.candidates[a];
          const std::vector<double>* cand_distance = distances_of(a);
          const Vec3 xa = position_of(p, a);
          const double* side_a =
              sides_of(a, xa);  // as cached at the classify, or the same values now
          if (side_a == nullptr) {
            side_scratch.resize(cand.size());
            for (std::size_t k = 0; k < cand.size(); ++k)
              side_scratch[k] = plane_side(face_normal_, face_offset_, cand[k], xa);
            side_a = side_scratch.data();
          }
          const double rho_a = rho0 + p.density_excess[a];
          const double inv_a = 1.0 / rho_a;
          const double p_a = p.pressure[a];
          const Vec3 va{p.velocity[0][a], p.velocity[1][a], p.velocity[2][a]};
          const Vec3 vva{p.viscous_velocity[0][a], p.viscous_velocity[1][a],
                         p.viscous_velocity[2][a]};
          double acc[3] = {0, 0, 0}, cont = 0, csum = 0, cg[3] = {0, 0, 0};
          // The free edges within the support (experiment fluid_state_round_free_edge).
          free_edges.clear();
          if (settings_.fluid_state_round_free_edge)
            for (const std::uint32_t t : cand)
              for (std::size_t e = 0; e < 3; ++e)
                if (mesh_.edge_on_boundary[t][e])
                  free_edges.push_back({mesh_.position[mesh_.triangles[t][e]],
                                        mesh_.position[mesh_.triangles[t][(e + 1) % 3]]});
          // One lattice behind each sheet (connected piece of the mesh with its images) within
          // the support: the nearest, and another facing the particle across a narrow gap (the
          // leaflet and its image in the coaptation plane 0.56 dp apart: a particle between them
          // needs the kernel filled behind both, or it is pushed into the gap).
          sheets.clear();
          sheets.push_back(s.near[a].closest);
          for (std::size_t k = 0; k < cand.size(); ++k) {
            const int piece = sheet_of_triangle_[cand[k]];
            bool known = false;
            for (const auto& seen : sheets)
              known = known || sheet_of_triangle_[seen.triangle] == piece;
            if (known) continue;
            one.clear();
            for (std::size_t m = k; m < cand.size(); ++m)
              if (sheet_of_triangle_[cand[m]] == piece) one.push_back(cand[m]);
            const ClosestPoint3 other = closest_point(mesh_, one, xa);
            // Seen directly, not through a nearer sheet (then its shadow is that sheet's).
            bool hidden = false;
            for (const std::uint32_t t : cand) {
              if (hidden || sheet_of_triangle_[t] == piece) continue;
              const double sp = dot(face_normal_[t], xa) - face_offset_[t],
                           sq = dot(face_normal_[t], other.point) - face_offset_[t];
              if (!may_meet(face_box_[t], sp, sq, xa, other.point)) continue;
              hidden = crossing(mesh_, t, xa, other.point).has_value();
            }
            if (other.distance < R && !hidden) sheets.push_back(other);
          }
          for (std::size_t sheet = 0; sheet < sheets.size(); ++sheet) {
            const ClosestPoint3& c = sheets[sheet];
            if (c.on_boundary && !settings_.lattice_beyond_free_edge) continue;
            const int only_piece = sheet == 0 ? -1 : sheet_of_triangle_[c.triangle];
            const int k_side = side_index(c.side);
            // Lattice axes: n from the closest point towards the particle (turns smoothly round a
            // free edge), t1 and t2 across it.
            Vec3 n = sub(xa, c.point);
            const double nl = norm(n);
            if (nl > 1e-9 * dp) {
              n = {n[0] / nl, n[1] / nl, n[2] / nl};
            } else {
              n = face_normal_[c.triangle];
              n = {c.side * n[0], c.side * n[1], c.side * n[2]};
            }
            const int least = std::abs(n[0]) <= std::abs(n[1]) && std::abs(n[0]) <= std::abs(n[2])
                                  ? 0
                                  : (std::abs(n[1]) <= std::abs(n[2]) ? 1 : 2);
            Vec3 e{0, 0, 0};
            e[static_cast<std::size_t>(least)] = 1.0;
            Vec3 t1 = cross(n, e);
            const double t1l = norm(t1);
            t1 = {t1[0] / t1l, t1[1] / t1l, t1[2] / t1l};
            const Vec3 t2 = cross(n, t1);
            // The shadow test's bounds (settings_.lattice_shadow_bounds). In the frame (t1, t2, n)
            // from the particle, x_v - x_a = (o1 + i delta, o2 + j delta, o3 - depth): a layer's
            // points lie in the plane zeta = o3 - depth < 0. A segment from the particle to one
            // of them can meet a triangle only at zeta in [o3 - depth, 0], so not one whose
            // corners all lie at zeta > 0 ("never"); and for one whose corners all lie at
            // zeta < 0, only where the point is the central projection of a point of the
            // triangle, inside the projected corners' bounding rectangle ("rectangle"). The
            // margins (1e-6 delta, and 1e-8 of the rectangle's reach times the corners' depth
            // spread) are far above round-off and the crossing test's 1e-12 tolerance, so every
            // skipped triangle is one the exact test would not hit: the same first hit.
            const bool use_bounds = settings_.lattice_shadow_bounds;
            const std::array<double, 3> frame = use_bounds ? frame_offsets(c.point, xa, t1, t2, n) : std::array<double, 3>{};
            const double zeta_margin = 1e-6 * delta;
            if (use_bounds) frame_shadow_bounds(mesh_, cand, xa, t1, t2, n, zeta_margin, 1e-3 * delta, bounds);
            const double first_depth =
                settings_.particle_aligned_layers ? delta - std::fmod(nl, delta) : 0.5 * delta;
            // Layers in front of the tangent plane too: on the concave side of a curved leaflet the
            // shadow reaches in front of it (R^2 / 2 rho_c: 0.4 dp at the sector's belly); the
            // shadow test keeps only the points behind the mesh.
            const int first_layer = settings_.lattice_in_front ? 1 - layers : 1;
            for (int l = first_layer; l <= layers; ++l) {
              const double depth = first_depth + (l - 1) * delta;
              if (depth <= -nl) continue;  // not beyond the particle's own position
              // x_a - x_v = (nl + depth) n - i delta t1 - j delta t2 (n, t1, t2 orthonormal), so
              // only |i|, |j| within the layer's disc can pass the r2 test below: the rest are
              // skipped before computing them. The bound is widened by 1e-6 of R^2, far above the
              // rounding of r2 and the particle's offset from the axis when nl ~ 0 (1e-9 dp): the
              // points tested, and their order, are those that passed before.
              const double along = nl + depth;
              const double room = R * R * (1.0 + 1e-6) - along * along;
              if (room < 0.0) continue;
              const int span_i = std::min(layers, static_cast<int>(std::sqrt(room) / delta));
              const double level = frame[2] - depth;  // the layer's zeta
              const bool bounded = use_bounds && level <= -zeta_margin;
              if (bounded) layer_shadow_bounds(level, frame[0], frame[1], delta, bounds);
              for (int i = -span_i; i <= span_i; ++i) {
                const double room_i = room - (i * delta) * (i * delta);
                if (room_i < 0.0) continue;
                const int span_j = std::min(layers, static_cast<int>(std::sqrt(room_i) / delta));
                for (int j = -span_j; j <= span_j; ++j) {
                  Vec3 xv;
                  for (int d = 0; d < 3; ++d)
                    xv[d] = c.point[d] + i * delta * t1[d] + j * delta * t2[d] - depth * n[d];
                  const Vec3 r = sub(xa, xv);
                  const double r2 = dot(r, r);
                  if (r2 >= R * R) continue;
                  // Beyond a free edge the lattice's middle column lies on the ray from the
                  // particle through the closest point on the edge: it only grazes the edge and
                  // stands for the fluid beyond it, so it is left out (as in 2D,
                  // two_sided_wall.cpp). Asked of the crossing test, it would count or not by
                  // round-off and the tolerance.
                  if (c.on_boundary && i == 0 && j == 0) continue;
                  // In the shadow: the segment from the particle to the point meets the mesh; the
                  // wall point q where it does carries the state. The candidates come nearest
                  // first, so the first hit is the one by the closest point (on a folded mesh
                  // the segment may meet it twice; the nearer triangle is the one in between).
                  std::optional<Crossing3> hit;
                  // Only candidates within |a x_v| of a can be met on the way (nearest first).
                  const double reach = cand_distance ? std::sqrt(r2) + reach_margin()
                                                     : std::numeric_limits<double>::infinity();
                  const double offset1 = i * delta, offset2 = j * delta;
                  for (std::size_t k = 0; k < cand.size() && !hit; ++k) {
                    if (cand_distance && (*cand_distance)[k] > reach) break;
                    if (bounded) {
                      if (bounds[k].misses(offset1, offset2)) continue;
                    }
                    const std::uint32_t t = cand[k];
                    const double sv = dot(face_normal_[t], xv) - face_offset_[t];
                    if (!may_meet(face_box_[t], side_a[k], sv, xa, xv)) continue;
                    hit = crossing(mesh_, t, xa, xv);
                  }
                  if (!hit) continue;
                  if (only_piece >= 0 && sheet_of_triangle_[hit->triangle] != only_piece)
                    continue;  // another sheet's shadow
                  const std::size_t t = hit->triangle;
                  const auto& tri = mesh_.triangles[t];
                  const int map = triangle_map_[t];
                  // Reachable round a free edge within the support: the fluid there is the other
                  // side's, flowing round the edge, not fluid moving with the wall (the 2D plate's
                  // lever on the edge's excess, docs/thin-leaflet.md).
                  bool round_edge = false;
                  for (std::size_t e = 0; e < free_edges.size() && !round_edge; ++e) {
                    const auto& [e0, e1] = free_edges[e];
                    if (distance_to_segment(xa, e0, e1) + distance_to_segment(xv, e0, e1) >= R)
                      continue;
                    round_edge = path_through_segment(xa, xv, e0, e1) < R;
                  }
                  const int k_state = round_edge ? 1 - k_side : k_side;
                  Vec3 q{0, 0, 0}, vw{0, 0, 0}, aw{0, 0, 0}, ve{0, 0, 0};
                  double p_v = 0;
                  for (int k = 0; k < 3; ++k) {
                    const double w = hit->barycentric[static_cast<std::size_t>(k)];
                    const std::uint32_t m = tri[static_cast<std::size_t>(k)];
                    const SideState& st =
                        s.state[origin_node_[m]].side[static_cast<std::size_t>(k_state)];
                    p_v += w * st.pressure;
                    const Vec3 vst = to_image(map, st.velocity);
                    for (int d = 0; d < 3; ++d) {
                      q[d] += w * mesh_.position[m][d];
                      vw[d] += w * mesh_velocity_[m][d];
                      aw[d] += w * mesh_acceleration_[m][d];
                      ve[d] += w * vst[d];
                    }
                  }
                  if (!settings_.wall_acceleration_in_pressure) aw = {0, 0, 0};
                  for (int d = 0; d < 3; ++d)
                    p_v += rho0 * (fluid_.gravity[d] - aw[d]) * (xv[d] - q[d]);
                  Vec3 vv_v;
                  for (int d = 0; d < 3; ++d) vv_v[d] = 2.0 * vw[d] - ve[d];  // no-slip
                  if (round_edge) vw = vv_v = ve;  // moves with that side's fluid
                  const double inv_v =
                      1.0 / (rho0 + eos.density_excess(p_v - fluid_.background_pressure));
                  const double dist = std::sqrt(r2);
                  const double F = W.gradient_factor(static_cast<float>(dist));
                  const double wv = W.value(static_cast<float>(dist));
                  const double inv_rr = inv_a * inv_v;
                  const double vdx =
                      (va[0] - vw[0]) * r[0] + (va[1] - vw[1]) * r[1] + (va[2] - vw[2]) * r[2];
                  double radial = -(p_a + p_v) * inv_rr;
                  if (alpha_c0 > 0)
                    radial +=
                        alpha_c0 * h * std::min(vdx, 0.0) / (r2 + eta2) * 0.5 * (inv_a + inv_v);
                  radial *= F;
                  const double viscous = two_mu * inv_rr * F;
                  Vec3 da;
                  for (int d = 0; d < 3; ++d)
                    da[d] = mass_v * (radial * r[d] + viscous * (vva[d] - vv_v[d]));
                  for (int d = 0; d < 3; ++d) acc[d] += da[d];
                  cont += mass_v * vdx * F;
                  csum += mass_v * wv * inv_v;
                  for (int d = 0; d < 3; ++d) cg[d] += mass_v * F * r[d] * inv_v;
                  // Action = reaction onto the nodes of the triangle seen, from the gauge pressure
                  // p - p_b (docs/thin-leaflet.md, "Coupled runs"); a load seen on a mirror image
                  // is the mirror fluid's load on the real leaflet, reflected back.
                  const double gauge = 2.0 * fluid_.background_pressure * inv_rr * F * mass_v;
                  Vec3 load;
                  for (int d = 0; d < 3; ++d) load[d] = -mass_a * (da[d] + gauge * r[d]);
                  load = to_real(map, load);
                  for (int k = 0; k < 3; ++k) {
                    const double w = hit->barycentric[static_cast<std::size_t>(k)];
                    auto& f = forces.at(origin_node_[tri[static_cast<std::size_t>(k)]]);
                    for (int d = 0; d < 3; ++d) f[d] += w * load[d];
                  }
                }
              }
            }
          }
          for (int d = 0; d < 3; ++d) p.acceleration[d][a] += static_cast<float>(acc[d]);
          p.density_rate[a] += static_cast<float>(cont);
          if (with_kernel_sum) {
            p.kernel_sum[a] += static_cast<float>(csum);
            for (int d = 0; d < 3; ++d) p.kernel_sum_gradient[d][a] += static_cast<float>(cg[d]);
          }
        }
        forces.close_block(static_cast<std::size_t>(block));
      }
    }
  });
  node_loads_.sum_into(s.force);
}

bool ThinWallModel3D::accept_shift(const Particles<3>& p, std::size_t i, const Vec<3>& shift) {
  const auto& s = dyn_;
  if (i >= s.near.size() || !s.near[i].near) return true;
  const Vec3 x = position_of(p, i);
  const Vec3 y{x[0] + shift[0], x[1] + shift[1], x[2] + shift[2]};
  const double reach = std::sqrt(shift[0] * shift[0] + shift[1] * shift[1] + shift[2] * shift[2]) + reach_margin();
  bool ok =
      !crosses_any_within(mesh_, s.candidates[i], distances_of(i), sides_of(i, x), reach, face_normal_, face_offset_, face_box_, x, y);
  if (ok) {
    const double after = closest_point(mesh_, s.candidates[i], y).distance;
    ok = !(after < clearance_ && after < s.near[i].closest.distance);
  }
  if (!ok) {
#pragma omp atomic
    ++dyn_.counters.rejected_shifts;
  }
  return ok;
}

void ThinWallModel3D::node_forces(std::span<Vec<3>> forces) const {
  if (forces.size() != node_count_)
    throw std::invalid_argument(fmt::format("thin wall node_forces: {} entries given: needs one per node ({})", forces.size(), node_count_));
  if (dyn_.force.size() != node_count_) {
    std::fill(forces.begin(), forces.end(), Vec<3>{0, 0, 0});
    return;
  }
  smoother_.apply(dyn_.x, dyn_.force, forces);
}

Vec3 ThinWallModel3D::total_force() const {
  Vec3 total{0, 0, 0};
  for (const auto& f : dyn_.force)
    for (int d = 0; d < 3; ++d) total[d] += f[d];
  return total;
}

std::size_t ThinWallModel3D::near_count() const {
  std::size_t n = 0;
  for (const auto& w : dyn_.near) n += w.near ? 1 : 0;
  return n;
}

void ThinWallModel3D::save_checkpoint() { checkpoint_ = dyn_; }

void ThinWallModel3D::restore_checkpoint() {
  if (!checkpoint_) throw std::logic_error("thin wall 3D restore_checkpoint: no checkpoint was saved");
  dyn_ = *checkpoint_;
  generation_ = next_generation();
  place_mesh();
}

std::optional<std::vector<NamedArray>> ThinWallModel3D::restart_state() const {
  const auto& s = dyn_;
  RestartWriter out;
  s.motion.save(out, "motion");
  out.vectors("nodes.x", s.x);
  out.vectors("nodes.v", s.v);
  out.vectors("nodes.a", s.a);
  // Before the first evaluation the states and loads are empty: written as their defaults.
  std::vector<std::array<double, 10>> states(node_count_, std::array<double, 10>{});
  for (std::size_t j = 0; j < std::min(s.state.size(), node_count_); ++j)
    for (std::size_t k = 0; k < 2; ++k) {
      const SideState& st = s.state[j].side[k];
      states[j][5 * k] = st.pressure;
      for (std::size_t d = 0; d < 3; ++d) states[j][5 * k + 1 + d] = st.velocity[d];
      states[j][5 * k + 4] = st.weight;
    }
  out.vectors("nodes.side_states", states);
  std::vector<Vec3> force = s.force;
  force.resize(node_count_, Vec3{0, 0, 0});
  out.vectors("nodes.force", force);
  std::vector<std::array<double, 11>> near(s.near.size());
  for (std::size_t i = 0; i < s.near.size(); ++i) {
    const ClosestPoint3& c = s.near[i].closest;
    near[i] = {s.near[i].near ? 1.0 : 0.0, static_cast<double>(c.triangle), c.barycentric[0], c.barycentric[1], c.barycentric[2],
               c.point[0], c.point[1], c.point[2], c.distance, static_cast<double>(c.side), c.on_boundary ? 1.0 : 0.0};
  }
  out.vectors("particles.near", near);
  out.lists("particles.candidates", s.candidates);
  out.vectors("particles.start_position", s.start_position);
  out.vectors("nodes.start_position", s.start_nodes);
  out.scalars("by_id.side", s.side_by_id);
  out.scalars("by_id.corrected", s.corrected_by_id);
  out.vectors("by_id.previous_position", s.previous_by_id);
  out.scalars("counters", std::vector<double>{static_cast<double>(s.counters.corrections), static_cast<double>(s.counters.leaks),
                                              static_cast<double>(s.counters.rejected_shifts)});
  return out.take();
}

void ThinWallModel3D::load_restart_state(std::span<const NamedArray> arrays) {
  const RestartReader in(arrays, "thin wall 3D restart state");
  Dynamic s = dyn_;
  s.motion.load(in, "motion");
  s.x = in.vectors<3>("nodes.x", node_count_);
  s.v = in.vectors<3>("nodes.v", node_count_);
  s.a = in.vectors<3>("nodes.a", node_count_);
  const auto states = in.vectors<10>("nodes.side_states", node_count_);
  s.state.assign(node_count_, NodeState{});
  for (std::size_t j = 0; j < node_count_; ++j)
    for (std::size_t k = 0; k < 2; ++k) {
      SideState& st = s.state[j].side[k];
      st.pressure = states[j][5 * k];
      for (std::size_t d = 0; d < 3; ++d) st.velocity[d] = states[j][5 * k + 1 + d];
      st.weight = states[j][5 * k + 4];
    }
  s.force = in.vectors<3>("nodes.force", node_count_);
  const auto near = in.vectors<11>("particles.near");
  s.near.assign(near.size(), NearWall{});
  for (std::size_t i = 0; i < near.size(); ++i) {
    const auto& e = near[i];
    if (e[1] < 0 || e[1] >= static_cast<double>(mesh_.triangles.size()))
      throw std::runtime_error(fmt::format("thin wall 3D restart state: array 'particles.near' names triangle {} for particle {}: "
                                           "allowed 0 to {}",
                                           e[1], i, mesh_.triangles.size() - 1));
    s.near[i].near = e[0] != 0.0;
    ClosestPoint3& c = s.near[i].closest;
    c.triangle = static_cast<std::size_t>(e[1]);
    c.barycentric = {e[2], e[3], e[4]};
    c.point = {e[5], e[6], e[7]};
    c.distance = e[8];
    c.side = static_cast<int>(e[9]);
    c.on_boundary = e[10] != 0.0;
  }
  s.candidates = in.lists("particles.candidates", near.size());
  s.candidate_distance.clear();  // not stored: the next classify rebuilds them (until then every candidate is tested)
  s.candidate_side.clear();
  s.classified_position.clear();
  for (const auto& list : s.candidates)
    for (const auto t : list)
      if (t >= mesh_.triangles.size())
        throw std::runtime_error(fmt::format("thin wall 3D restart state: array 'particles.candidates.values' names triangle {}: "
                                             "allowed 0 to {}",
                                             t, mesh_.triangles.size() - 1));
  s.start_position = in.vectors<3>("particles.start_position");
  s.start_nodes = in.vectors<3>("nodes.start_position");
  if (!s.start_nodes.empty() && s.start_nodes.size() != mesh_.position.size())
    throw std::runtime_error(fmt::format("thin wall 3D restart state: array 'nodes.start_position' has {} nodes: allowed 0 or {} "
                                         "(the leaflet with its mirror images)",
                                         s.start_nodes.size(), mesh_.position.size()));
  s.side_by_id = in.scalars<std::int8_t>("by_id.side");
  s.corrected_by_id = in.scalars<std::uint8_t>("by_id.corrected");
  s.previous_by_id = in.vectors<3>("by_id.previous_position");
  const auto counters = in.scalars<std::size_t>("counters", 3);
  s.counters = {counters[0], counters[1], counters[2]};
  dyn_ = std::move(s);
  generation_ = next_generation();
  place_mesh();
}

std::unique_ptr<ImmersedSurfaceModel<3>> make_thin_wall_model_3d(const ImmersedSurfaceGeometry<3>& geometry,
                                                                 const FluidSettings<3>& fluid,
                                                                 const valvefsi::cases::FluidThinWalls& walls) {
  valvefsi::cases::FluidThinWalls checked = walls;
  const bool spacing_given = walls.has_virtual_spacing_ratio();
  apply_field_limits(checked, "fluid case", "fluid.thin_walls");
  // The 3D sector closes onto its coaptation plane and the full valve's free edges meet along
  // lines: the 2D bridge between two end points does not carry over.
  if (checked.coaptation_distance() > 0.0)
    throw valvefsi::CaseError(fmt::format("fluid case: fluid.thin_walls.coaptation_distance = {} m: allowed only 0 in 3D (the "
                                          "coaptation bridge joins the free ends of a 2D section)",
                                          checked.coaptation_distance()));
  ThinWall3DSettings settings;
  if (spacing_given) settings.virtual_spacing_ratio = checked.virtual_spacing_ratio();
  settings.clearance_ratio = checked.clearance_ratio();
  settings.wall_acceleration_in_pressure = checked.wall_acceleration_in_pressure();
  settings.load_smoothing_radius_ratio = checked.load_smoothing_radius_ratio();
  return std::make_unique<ThinWallModel3D>(geometry, fluid, settings);
}

}  // namespace valvefsi::fluid::thin_wall
