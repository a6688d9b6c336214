// Geometry of the 3D thin wall (triangle mesh) with exact answers, the 3D counterparts of
// test_geometry.cpp: closest point and side from the nearest feature's pseudo-normal (also
// across a fold), free-boundary flag, segment crossing, and the swept crossing of a moving
// point against a moving mesh (one event crosses, out-and-back does not, a shared edge counts
// once).
#include <gtest/gtest.h>

#include <cmath>

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

}  // namespace
}  // namespace valvefsi::fluid::thin_wall
