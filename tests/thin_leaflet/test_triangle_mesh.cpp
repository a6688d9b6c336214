// Geometry of the 3D thin wall (triangle mesh) with exact answers, the 3D counterparts of
// test_geometry.cpp: closest point and side from the nearest feature's pseudo-normal (also
// across a fold), free-boundary flag, segment crossing, and the swept crossing of a moving
// point against a moving mesh (one event crosses, out-and-back does not, a shared edge counts
// once), and the bucket grid's cached neighbourhoods against the brute-force search.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "valvefsi/fluid/thin_wall/triangle_mesh.hpp"

namespace valvefsi::fluid::thin_wall {
namespace {

// The unit square z = 0 as two triangles, normals +z.
TriangleMesh square() {
  TriangleMesh m;
  m.position = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  m.update();
  return m;
}

// Two unit squares folded along x = 1: z = 0 for x in [0, 1], then rising at 90 degrees
// (x = 1, z in [0, 1]); normals +z on the flat part and -x on the upright part.
TriangleMesh fold() {
  TriangleMesh m;
  m.position = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {1, 0, 1}, {1, 1, 1}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}, {1, 4, 5}, {1, 5, 2}};
  m.update();
  return m;
}

TEST(ThinWallTriangleMesh, ClosestPointSideAndBoundaryOnASquare) {
  const auto m = square();
  auto c = closest_point(m, {0.25, 0.5, 0.3});
  EXPECT_NEAR(c.distance, 0.3, 1e-15);
  EXPECT_NEAR(c.point[0], 0.25, 1e-15);
  EXPECT_NEAR(c.point[1], 0.5, 1e-15);
  EXPECT_EQ(c.side, 1);
  EXPECT_FALSE(c.on_boundary);
  c = closest_point(m, {0.6, 0.3, -0.2});
  EXPECT_EQ(c.side, -1);
  EXPECT_NEAR(c.distance, 0.2, 1e-15);
  // On the diagonal (the shared edge), inside: not the boundary.
  c = closest_point(m, {0.5, 0.5, 0.1});
  EXPECT_FALSE(c.on_boundary);
  EXPECT_EQ(c.side, 1);
  // Beyond the edge x = 1: closest point on it, flagged as the free boundary.
  c = closest_point(m, {1.5, 0.5, 0.2});
  EXPECT_TRUE(c.on_boundary);
  EXPECT_NEAR(c.point[0], 1.0, 1e-15);
  EXPECT_NEAR(c.distance, std::hypot(0.5, 0.2), 1e-15);
  EXPECT_EQ(c.side, 1);
  // Beyond the corner (1, 1): the vertex.
  c = closest_point(m, {2.0, 3.0, -1.0});
  EXPECT_TRUE(c.on_boundary);
  EXPECT_NEAR(c.distance, std::sqrt(1.0 + 4.0 + 1.0), 1e-14);
  EXPECT_EQ(c.side, -1);
}

TEST(ThinWallTriangleMesh, SideAcrossAFoldFromTheEdgesPseudoNormal) {
  const auto m = fold();
  // The fold's inside (side +1 of both faces) is x < 1, z > 0. (1.5, 0.5, -0.1) is nearest
  // to the fold edge; its pseudo-normal (-1, 0, 1) gives (0.5, 0, -0.1) . (-1, 0, 1) < 0.
  auto c = closest_point(m, {1.5, 0.5, -0.1});
  EXPECT_NEAR(c.distance, std::sqrt(0.26), 1e-14);
  EXPECT_EQ(c.side, -1);
  EXPECT_FALSE(c.on_boundary);
  // Inside the fold (x < 1, z > 0): side +1 of both faces.
  c = closest_point(m, {0.8, 0.5, 0.3});
  EXPECT_EQ(c.side, 1);
  // Beside the upright part (x > 1): side -1 of its face (-x), though the point is above the
  // flat part's plane (its normal alone would say +1).
  c = closest_point(m, {1.3, 0.5, 0.5});
  EXPECT_NEAR(c.distance, 0.3, 1e-14);
  EXPECT_EQ(c.side, -1);
}

TEST(ThinWallTriangleMesh, SegmentCrossing) {
  const auto m = square();
  auto c = first_crossing(m, {0.3, 0.6, 1.0}, {0.3, 0.6, -1.0});
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->s, 0.5, 1e-15);
  EXPECT_FALSE(first_crossing(m, {0.3, 0.6, 1.0}, {0.3, 0.6, 0.5}).has_value());
  EXPECT_FALSE(first_crossing(m, {1.3, 0.6, 1.0}, {1.3, 0.6, -1.0}).has_value());  // past the edge
  // Touching counts (blocking is conservative): ends on the square.
  EXPECT_TRUE(first_crossing(m, {0.3, 0.6, 1.0}, {0.3, 0.6, 0.0}).has_value());
  // Through the shared diagonal.
  EXPECT_TRUE(first_crossing(m, {0.5, 0.5, 1.0}, {0.5, 0.5, -1.0}).has_value());
}

TEST(ThinWallTriangleMesh, SweptCrossingOfAMovingPointAgainstAMovingMesh) {
  const auto m = square();
  const std::vector<Vec3> before = m.position;
  std::vector<Vec3> after = m.position;
  for (auto& x : after) x[2] += 0.5;  // the square rises by 0.5
  // A point at rest at z = 0.25: the square sweeps through it at tau = 0.5.
  auto c = swept_crossing(m, before, after, {0.3, 0.4, 0.25}, {0.3, 0.4, 0.25});
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->tau, 0.5, 1e-12);
  // A point rising from 0.1 to 0.9 while the square rises to 0.5 stays above it: no crossing.
  EXPECT_FALSE(swept_crossing(m, before, after, {0.3, 0.4, 0.1}, {0.3, 0.4, 0.9}).has_value());
  // Beside the square: no crossing.
  EXPECT_FALSE(swept_crossing(m, before, after, {1.3, 0.4, 0.25}, {1.3, 0.4, 0.25}).has_value());
  // Through the shared diagonal: one event, not two.
  c = swept_crossing(m, before, after, {0.5, 0.5, 0.25}, {0.5, 0.5, 0.25});
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->tau, 0.5, 1e-12);
  // A tilting square: nodes 1 and 2 (x = 1) rise by 2, so the surface is z = 2 tau x and
  // meets the point (0.9, 0.1, 0.5) at tau = 0.5 / 1.8.
  std::vector<Vec3> tilted = m.position;
  tilted[1][2] = 2.0;
  tilted[2][2] = 2.0;
  c = swept_crossing(m, before, tilted, {0.9, 0.1, 0.5}, {0.9, 0.1, 0.5});
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->tau, 0.5 / 1.8, 1e-12);
}

// The classify's cached search (the bucket grid's per-cell neighbourhoods, then the exact
// distance behind a box test) finds exactly the brute-force answer over every triangle: the same
// triangles in the same order with bit-identical distances, for points inside, beside and
// outside the grid, on a warped sheet with a scatter of loose triangles; and the first found is
// the closest point over all found, bit for bit.
TEST(ThinWallTriangleMesh, CachedNeighbourhoodsFindWhatTheBruteForceSearchFinds) {
  std::uint64_t state = 2026;
  auto uniform = [&state] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / 9007199254740992.0;
  };
  TriangleMesh m;
  const int n = 14;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = i / double(n), y = j / double(n);
      m.position.push_back({x, y, 0.15 * std::sin(5 * x) * std::cos(4 * y) + 0.01 * uniform()});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const auto a = static_cast<std::uint32_t>(j * (n + 1) + i);
      m.triangles.push_back({a, a + 1, a + n + 2});
      m.triangles.push_back({a, a + n + 2, a + n + 1});
    }
  for (int t = 0; t < 60; ++t) {  // loose triangles of all sizes up to a cell
    const Vec3 c{uniform(), uniform(), 0.6 * uniform() - 0.3};
    const auto first = static_cast<std::uint32_t>(m.position.size());
    for (int k = 0; k < 3; ++k) m.position.push_back({c[0] + 0.2 * uniform(), c[1] + 0.2 * uniform(), c[2] + 0.2 * uniform()});
    m.triangles.push_back({first, first + 1, first + 2});
  }
  m.update();
  std::vector<std::uint32_t> all(m.triangles.size());
  for (std::size_t t = 0; t < all.size(); ++t) all[t] = static_cast<std::uint32_t>(t);
  const auto boxes = triangle_boxes(m);
  const double R = 0.11;
  TriangleBuckets buckets;
  buckets.build(boxes, R);
  buckets.cache_neighbourhoods();
  std::vector<std::uint32_t> expected, found, scratch, queried;
  std::vector<double> expected_distance, found_distance;
  std::size_t near = 0;
  for (int k = 0; k < 20000; ++k) {
    const Vec3 x{1.4 * uniform() - 0.2, 1.4 * uniform() - 0.2, 0.9 * uniform() - 0.45};
    const Vec3 lower{x[0] - R, x[1] - R, x[2] - R}, upper{x[0] + R, x[1] + R, x[2] + R};
    triangles_within(m, all, x, R, expected, expected_distance);
    const auto around = buckets.around(lower, upper, scratch);
    triangles_within(m, boxes, around, x, R, found, found_distance);
    ASSERT_EQ(found, expected) << "point " << k;
    ASSERT_EQ(found_distance, expected_distance) << "point " << k;  // bit for bit
    buckets.query(lower, upper, queried);
    ASSERT_TRUE(std::is_sorted(around.begin(), around.end()));
    ASSERT_TRUE(std::includes(around.begin(), around.end(), queried.begin(), queried.end())) << "point " << k;
    if (!expected.empty()) {
      // The nearest found is closest_point's answer over those found (the classify asks only
      // it; over all triangles in index order a tie of distances may pick another).
      ++near;
      const auto all_of = closest_point(m, found, x), first = closest_point(m, std::vector<std::uint32_t>{found[0]}, x);
      ASSERT_EQ(first.triangle, all_of.triangle) << "point " << k;
      ASSERT_EQ(first.barycentric, all_of.barycentric);
      ASSERT_EQ(first.point, all_of.point);
      ASSERT_EQ(first.distance, all_of.distance);
      ASSERT_EQ(first.side, all_of.side);
      ASSERT_EQ(first.on_boundary, all_of.on_boundary);
    }
  }
  EXPECT_GT(near, 5000u);
}

}  // namespace
}  // namespace valvefsi::fluid::thin_wall
