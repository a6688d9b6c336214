// 2D dam break (water column 1 m wide, 2 m high, tank 4 m) against the surge-front positions
// measured by Martin & Moyce (1952), data in data/dam-break-front-martin-moyce-1952.csv:
// coarse (dp = 0.04 m) for CI; the comparison and its bounds are in dam_break_front.hpp.
#include <gtest/gtest.h>

#include "dam_break_front.hpp"

namespace valvefsi::fluid {
namespace {

TEST(DamBreak, CoarseFrontFollowsMartinMoyce) {
  const auto r = testing::compare_dam_break_front(0.04);
  testing::expect_front_follows_martin_moyce(r, 0.04);
}

}  // namespace
}  // namespace valvefsi::fluid
