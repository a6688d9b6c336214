// The dam break of test_dam_break.cpp at dp = 0.02 m and 0.01 m (about 21k particles, the
// benchmark resolution): validation, run with ctest -L validation.
#include <gtest/gtest.h>

#include <cmath>

#include "dam_break_front.hpp"

namespace valvefsi::fluid {
namespace {

TEST(DamBreakValidation, FrontFollowsMartinMoyceAtTwoResolutions) {
  const auto coarse = testing::compare_dam_break_front(0.02);
  testing::expect_front_follows_martin_moyce(coarse, 0.02);
  const auto fine = testing::compare_dam_break_front(0.01);
  testing::expect_front_follows_martin_moyce(fine, 0.01);
  // The start-up delay is the experiment's, not a resolution effect: it settles as dp falls.
  EXPECT_LT(std::abs(fine.shift - coarse.shift), 0.05);
}

}  // namespace
}  // namespace valvefsi::fluid
