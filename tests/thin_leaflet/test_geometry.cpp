// Geometry of the 2D thin wall with exact answers: closest point and side (from the nearest
// segment, pseudo-normal at a bend), straight-segment crossing (pair blocking), the swept
// crossing of a moving point against a moving wall, and marker sampling.
#include <gtest/gtest.h>

#include <cmath>

#include "valvefsi/fluid/thin_wall/markers.hpp"
#include "valvefsi/fluid/thin_wall/polyline.hpp"

namespace valvefsi::fluid::thin_wall {
namespace {

TEST(ThinWallGeometry, ClosestPointAndSideOfAStraightWall) {
  const auto wall = Polyline::at_rest({{0.0, 0.0}, {2.0, 0.0}});
  auto c = closest_point(wall, {1.0, 0.5});
  EXPECT_EQ(c.segment, 0u);
  EXPECT_DOUBLE_EQ(c.t, 0.5);
  EXPECT_DOUBLE_EQ(c.distance, 0.5);
  EXPECT_EQ(c.side, 1);  // the left normal of a +x tangent is +y
  EXPECT_FALSE(c.at_free_end);
  c = closest_point(wall, {1.5, -0.3});
  EXPECT_DOUBLE_EQ(c.t, 0.75);
  EXPECT_EQ(c.side, -1);
  // Beyond the tip: the closest point is the end node, flagged as a free end.
  c = closest_point(wall, {3.0, 0.2});
  EXPECT_DOUBLE_EQ(c.t, 1.0);
  EXPECT_TRUE(c.at_free_end);
  EXPECT_DOUBLE_EQ(c.distance, std::sqrt(1.04));
  EXPECT_EQ(c.side, 1);
}

TEST(ThinWallGeometry, SideAtABendUsesTheNearestSegmentsNotOneNormal) {
  // An L turning left at (1, 0). Outside the corner the nearest feature is the vertex: its
  // side comes from the pseudo-normal (-1, 1): (2, -1) lies outside the corner, side -1.
  const auto wall = Polyline::at_rest({{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}});
  auto c = closest_point(wall, {2.0, -1.0});
  EXPECT_DOUBLE_EQ(c.distance, std::sqrt(2.0));
  EXPECT_FALSE(c.at_free_end);
  EXPECT_EQ(c.side, -1);
  // (1.5, 0.5): nearest is the second segment (distance 0.5); a single marker at the first
  // segment's midpoint (0.5, 0) with normal +y would call it side +1, the nearest segment -1.
  c = closest_point(wall, {1.5, 0.5});
  EXPECT_EQ(c.segment, 1u);
  EXPECT_DOUBLE_EQ(c.distance, 0.5);
  EXPECT_EQ(c.side, -1);
  // Inside the L: equidistant from both segments, both agree on side +1.
  c = closest_point(wall, {0.5, 0.5});
  EXPECT_DOUBLE_EQ(c.distance, 0.5);
  EXPECT_EQ(c.side, 1);
  // Candidates restrict the search.
  c = closest_point(wall, std::vector<std::uint32_t>{1u}, {0.5, -0.5});
  EXPECT_EQ(c.segment, 1u);
  EXPECT_DOUBLE_EQ(c.t, 0.0);
}

TEST(ThinWallGeometry, StraightSegmentCrossing) {
  const auto wall = Polyline::at_rest({{0.0, 0.0}, {1.0, 0.0}, {2.0, 0.0}});
  auto c = first_crossing(wall, {1.5, -1.0}, {1.5, 1.0});
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->segment, 1u);
  EXPECT_DOUBLE_EQ(c->t, 0.5);
  EXPECT_DOUBLE_EQ(c->s, 0.5);
  c = first_crossing(wall, {0.25, 0.75}, {0.75, -0.25});  // crosses at (0.625, 0)
  ASSERT_TRUE(c.has_value());
  EXPECT_DOUBLE_EQ(c->t, 0.625);
  EXPECT_DOUBLE_EQ(c->s, 0.75);
  EXPECT_FALSE(crosses(wall, {3.0, -1.0}, {3.0, 1.0}));   // beyond the tip
  EXPECT_FALSE(crosses(wall, {1.0, 0.1}, {1.0, 1.0}));    // stays on one side
  EXPECT_TRUE(crosses(wall, {2.0, -1.0}, {2.0, 1.0}));    // through the tip node (conservative)
}

TEST(ThinWallGeometry, SweptCrossingInTheWallsMovingFrame) {
  const std::vector<Vec2> before{{0.0, 0.0}, {2.0, 0.0}};
  // The wall rises by 1 through a particle at rest at height 0.5: met half-way.
  auto hit = swept_crossing(before, {{0.0, 1.0}, {2.0, 1.0}}, {1.0, 0.5}, {1.0, 0.5});
  ASSERT_TRUE(hit.has_value());
  EXPECT_DOUBLE_EQ(hit->tau, 0.5);
  EXPECT_DOUBLE_EQ(hit->t, 0.5);
  // A particle carried with the wall never meets it although its path crosses y = 0.5 ... 1.5.
  EXPECT_FALSE(swept_crossing(before, {{0.0, 1.0}, {2.0, 1.0}}, {1.0, 0.5}, {1.0, 1.5}).has_value());
  // A particle that stays at y = 0.5 while the wall rises only to 0.4 is not met.
  EXPECT_FALSE(swept_crossing(before, {{0.0, 0.4}, {2.0, 0.4}}, {1.0, 0.5}, {1.0, 0.5}).has_value());
  // Rotation about the first node by 90 degrees (nodes move linearly): the free node passes
  // (2 - 2 tau, 2 tau), and the particle at (0.5, 0.5) is on the wall's line when
  // cross(B, X) = 0.5 (2 - 2 tau) - 0.5 (2 tau) = 0, i.e. tau = 1/2, at t = X.B / B.B = 1/2.
  hit = swept_crossing(before, {{0.0, 0.0}, {0.0, 2.0}}, {0.5, 0.5}, {0.5, 0.5});
  ASSERT_TRUE(hit.has_value());
  EXPECT_DOUBLE_EQ(hit->tau, 0.5);
  EXPECT_DOUBLE_EQ(hit->t, 0.5);
  // Beyond the reach of the rotating wall: no event.
  EXPECT_FALSE(swept_crossing(before, {{0.0, 0.0}, {0.0, 2.0}}, {2.0, 2.0}, {2.0, 2.0}).has_value());
  // A static wall: passing beyond the tip is no crossing, passing through it is.
  EXPECT_FALSE(swept_crossing(before, before, {3.0, -1.0}, {3.0, 1.0}).has_value());
  hit = swept_crossing(before, before, {0.5, -1.0}, {0.5, 3.0});
  ASSERT_TRUE(hit.has_value());
  EXPECT_DOUBLE_EQ(hit->tau, 0.25);
  EXPECT_DOUBLE_EQ(hit->t, 0.25);
  // Through an interior node of a three-node wall: counted once, so still a crossing.
  const std::vector<Vec2> bent{{0.0, 0.0}, {1.0, 0.0}, {2.0, 0.0}};
  EXPECT_TRUE(swept_crossing(bent, bent, {1.0, -1.0}, {1.0, 1.0}).has_value());
}

TEST(ThinWallGeometry, MarkersTileTheWallAndInterpolateConservatively) {
  const auto wall = Polyline::at_rest({{0.0, 0.0}, {1.0, 0.0}, {1.0, 2.0}});
  MarkerSet markers(wall, 0.3);
  // Segment 0: round(1 / 0.3) = 3 markers of 1/3; segment 1: round(2 / 0.3) = 7 markers of 2/7.
  ASSERT_EQ(markers.size(), 10u);
  EXPECT_DOUBLE_EQ(markers[0].area, 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(markers[0].arc_length, 1.0 / 6.0);
  EXPECT_DOUBLE_EQ(markers[3].area, 2.0 / 7.0);
  EXPECT_DOUBLE_EQ(markers[3].arc_length, 1.0 + 1.0 / 7.0);
  double total = 0;
  for (const auto& m : markers.markers()) total += m.area;
  EXPECT_DOUBLE_EQ(total, 3.0);
  EXPECT_DOUBLE_EQ(markers.total_length(), 3.0);
  EXPECT_DOUBLE_EQ(markers.arc_length(1, 0.5), 2.0);
  // Halfway between markers 1 (s = 1/2) and 2 (s = 5/6).
  const auto w = markers.weights_at(2.0 / 3.0);
  EXPECT_EQ(w.first, 1u);
  EXPECT_EQ(w.second, 2u);
  EXPECT_NEAR(w.w0, 0.5, 1e-14);
  EXPECT_NEAR(w.w1, 0.5, 1e-14);
  // Ends clamp to the end markers.
  EXPECT_EQ(markers.weights_at(0.0).first, 0u);
  EXPECT_EQ(markers.weights_at(3.0).first, 9u);
  // Node forces keep the total.
  for (std::size_t m = 0; m < markers.size(); ++m) markers[m].force = {1.0 * static_cast<double>(m), -2.0};
  const auto nodes = markers.node_forces(wall.node_count());
  const Vec2 sum{nodes[0][0] + nodes[1][0] + nodes[2][0], nodes[0][1] + nodes[1][1] + nodes[2][1]};
  EXPECT_NEAR(sum[0], 45.0, 1e-12);
  EXPECT_NEAR(sum[1], -20.0, 1e-12);
  EXPECT_NEAR(markers.total_force()[0], 45.0, 1e-12);
}

}  // namespace
}  // namespace valvefsi::fluid::thin_wall
