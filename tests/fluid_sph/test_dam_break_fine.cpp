// The dam break of test_dam_break.cpp at dp = 0.02 m and 0.01 m (about 21k particles, the
// benchmark resolution): validation, run with ctest -L validation.
#include <gtest/gtest.h>

#include "dam_break_front.hpp"

namespace valvefsi::fluid {
namespace {

TEST(DamBreakValidation, FrontFollowsMartinMoyceAtTwoResolutions) {
  for (double dp : {0.02, 0.01}) {
    double lost = 0;
    const double worst = testing::worst_front_error(dp, &lost);
    EXPECT_EQ(lost, 0) << "dp = " << dp;
    EXPECT_LT(worst, 0.15) << "dp = " << dp;
  }
}

}  // namespace
}  // namespace valvefsi::fluid
