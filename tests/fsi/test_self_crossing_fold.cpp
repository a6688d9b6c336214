// The cycle-2 leak of the coarse 2D valve (docs/fsi-2d.md, session 7): a leaflet that folds
// through itself sweeps a fluid particle with two of its segments in one step. The swept test
// then sees an even number of events (no put-back), yet the particle's side, taken from the
// closest segment, flips: the thin wall counts a leak. No put-back rule can be right where the
// wall crosses itself; the cure is the solid's self-contact, which keeps the folds apart.
#include <gtest/gtest.h>

#include <vector>

#include "valvefsi/fluid/thin_wall/polyline.hpp"

namespace tw = valvefsi::fluid::thin_wall;

namespace {

// A hairpin fold (mm): the lower arm (segment 0) and the upper arm (segment 2) joined at x = 2.
std::vector<tw::Vec2> hairpin(double lower_y, double upper_y) {
  return {{0.0, lower_y}, {2.0, lower_y}, {2.0, upper_y}, {0.0, upper_y}};
}

}  // namespace

TEST(SelfCrossingFold, TwoArmsSweepingOneParticleLeaveNoOddCrossingButFlipItsSide) {
  // The arms pass through each other over the step: the lower one from y = 0 to 1.1, the upper
  // one from 1 to -0.3; the particle between them stays at (1, 0.5).
  const auto before = hairpin(0.0, 1.0);
  const auto after = hairpin(1.1, -0.3);
  const tw::Vec2 x{1.0, 0.5};

  // Both arms swept it: two events, an even count, so correct_crossings puts nothing back.
  EXPECT_FALSE(tw::swept_crossing(before, after, x, x).has_value());
  // Each arm alone swept it once.
  EXPECT_TRUE(tw::swept_crossing(before, after, std::vector<std::uint32_t>{0}, x, x).has_value());
  EXPECT_TRUE(tw::swept_crossing(before, after, std::vector<std::uint32_t>{2}, x, x).has_value());

  const auto side_before = tw::closest_point(tw::Polyline::at_rest(before), x);
  const auto side_after = tw::closest_point(tw::Polyline::at_rest(after), x);
  EXPECT_EQ(side_before.segment, 0u);  // 0.5 from either arm: the lower index
  EXPECT_EQ(side_after.segment, 0u);   // 0.6 from the lower arm, 0.8 from the upper one
  EXPECT_FALSE(side_after.at_free_end);
  // Inside the fold before; outside the (now crossed) lower arm after: the side flipped without
  // a put-back, which classify reports as a leak once the particle's next step crosses the wall.
  EXPECT_NE(side_before.side, side_after.side);
  // The arms passed through each other: the fold is turned inside out, the lower arm now above
  // the upper one (in the valve they cross as an X; the sides are as undefined).
  EXPECT_GT(after[0][1], x[1]);
  EXPECT_LT(after[3][1], x[1]);
}

TEST(SelfCrossingFold, FoldsKeptApartSweepTheParticleOnceOrNotAtAll) {
  // With the arms held apart (self-contact keeps them at least a thickness apart), only one arm
  // moves past the particle: an odd count, so the put-back catches it.
  const auto before = hairpin(0.0, 1.0);
  const auto after = hairpin(0.7, 1.0);  // the lower arm passes the particle, the upper one stays
  const tw::Vec2 x{1.0, 0.5};
  const auto hit = tw::swept_crossing(before, after, x, x);
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(hit->segment, 0u);
}
