// 2D dam break (water column 1 m wide, 2 m high, tank 4 m) against the surge-front positions
// measured by Martin & Moyce (1952), data in data/dam-break-front-martin-moyce-1952.csv.
#include <gtest/gtest.h>

#include "dam_break_front.hpp"

namespace valvefsi::fluid {
namespace {

TEST(DamBreak, CoarseFrontFollowsMartinMoyce) {
  double lost = 0;
  const double worst = testing::worst_front_error(0.04, &lost);
  EXPECT_EQ(lost, 0);
  EXPECT_LT(worst, 0.15);
}

}  // namespace
}  // namespace valvefsi::fluid
