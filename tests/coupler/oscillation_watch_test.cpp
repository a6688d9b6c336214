// The coupler's slow-runaway watch (OscillationWatch, coupling.runaway_oscillation_speed) on
// velocity histories with known answers: a motion smooth over a window is not an oscillation,
// however fast or fast-growing; a period-4 mode (the serial-explicit piston's at mu = 2) is
// measured exactly; a jolt and a steady oscillation are not runaways; a growing period-4 mode
// fires at the first block above the floor, having grown by exactly r^16 per block; an
// oscillation that saturates at once and stands is caught by the standing rule, a shorter jolt is not.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>

#include "valvefsi/coupler/oscillation_watch.hpp"

namespace valvefsi::coupler {
namespace {

constexpr int kBlock = OscillationWatch::kBlockWindows;

// Two nodes: node 0 at rest, node 1 moving along x at v(n).
Eigen::Matrix3Xd velocities(double v) {
  Eigen::Matrix3Xd m = Eigen::Matrix3Xd::Zero(3, 2);
  m(0, 1) = v;
  return m;
}

struct Fired {
  int window = -1;
  OscillationWatch::Alarm alarm;
};

template <class V>
std::optional<Fired> feed(OscillationWatch& watch, int windows, V v, std::vector<double>* blocks = nullptr) {
  double last = 0.0;
  for (int n = 0; n < windows; ++n) {
    const double value = watch.update(velocities(v(n)));
    if (blocks && value != last) blocks->push_back(value);
    last = value;
    if (watch.alarm()) return Fired{n, *watch.alarm()};
  }
  return std::nullopt;
}

TEST(OscillationWatch, SmoothMotionIsNotAnOscillationHoweverFastOrFastGrowing) {
  // 5 m/s, 200 windows per period: the velocity's second difference is (2 pi / 200)^2 x 5 m/s at most.
  OscillationWatch sine(0.5, 4);
  std::vector<double> blocks;
  EXPECT_FALSE(feed(sine, 2000, [](int n) { return 5.0 * std::sin(2.0 * std::numbers::pi * n / 200.0); }, &blocks));
  ASSERT_EQ(blocks.size(), (2000u - 2u) / kBlock);
  const double bound = 5.0 * std::pow(2.0 * std::numbers::pi / 200.0, 2);
  for (double b : blocks) EXPECT_LE(b, bound);
  // Exponential growth with a time constant of 100 windows, to 22 m/s: smooth, so a ratio
  // 1 - 2 e^-0.01 + e^-0.02 = 9.9e-5 of the speed, below the floor.
  OscillationWatch growth(0.5, 4);
  EXPECT_FALSE(feed(growth, 1000, [](int n) { return 1e-3 * std::exp(n / 100.0); }));
}

TEST(OscillationWatch, PeriodFourModeMeasuredExactlyAndASteadyOneDoesNotFire) {
  // v = A cos(pi n / 2): v_n - 2 v_{n-1} + v_{n-2} = -2 A cos(pi (n - 1) / 2), RMS sqrt(2) A.
  OscillationWatch watch(0.5, 4);
  std::vector<double> blocks;
  const double amplitude = 3.0;
  EXPECT_FALSE(feed(watch, 40 * kBlock, [&](int n) { return amplitude * std::cos(std::numbers::pi * n / 2.0); }, &blocks));
  ASSERT_FALSE(blocks.empty());
  EXPECT_NEAR(blocks.front(), std::sqrt(2.0) * amplitude, 1e-12);
}

TEST(OscillationWatch, AJoltAboveTheFloorRisesForOneBlockAndIsNotARunaway) {
  // A tip stopped from 3 m/s within one window (the impact at closure), then at rest.
  OscillationWatch watch(0.5, 4);
  std::vector<double> blocks;
  EXPECT_FALSE(feed(watch, 20 * kBlock, [](int n) { return n < 50 ? 3.0 : 0.0; }, &blocks));
  // The jumps -3 and +3 m/s fall in one block: sqrt(18 / 16) m/s, then nothing.
  EXPECT_NEAR(*std::max_element(blocks.begin(), blocks.end()), std::sqrt(18.0 / kBlock), 1e-12);
  EXPECT_EQ(blocks.back(), 0.0);
}

TEST(OscillationWatch, GrowingPeriodFourModeFiresAtTheFirstBlockAboveTheFloor) {
  // The serial-explicit acoustic piston at mu = 2.02: roots of z^2 - (1 - mu/2) z + mu/2 = 0,
  // |z| = sqrt(mu / 2), argument ~ pi / 2. The jumps repeat every 16 windows scaled by |z|^16,
  // so each block is exactly (mu/2)^8 times the one before.
  const double r = std::sqrt(1.01);
  OscillationWatch watch(0.5, 4);
  std::vector<double> blocks;
  const auto fired = feed(watch, 4000, [&](int n) { return 1e-3 * std::pow(r, n) * std::cos(std::numbers::pi * n / 2.0); }, &blocks);
  ASSERT_TRUE(fired);
  ASSERT_GE(blocks.size(), 6u);
  for (std::size_t k = 1; k < blocks.size(); ++k) EXPECT_NEAR(blocks[k] / blocks[k - 1], std::pow(1.01, 8), 1e-9);
  EXPECT_GE(blocks.back(), 0.5);
  EXPECT_LT(blocks[blocks.size() - 2], 0.5);  // not one block later than needed
  EXPECT_EQ(fired->window, 2 + static_cast<int>(blocks.size()) * kBlock - 1);
  EXPECT_EQ(fired->alarm.node, 1);
  EXPECT_DOUBLE_EQ(fired->alarm.oscillation, blocks.back());
  EXPECT_NEAR(fired->alarm.oscillation_before, blocks.back() / std::pow(1.01, 32), 1e-12);
  // The same mode with the watch off (floor 0) is measured alike and never fires.
  OscillationWatch off(0.0, 4);
  EXPECT_FALSE(feed(off, 4000, [&](int n) { return 1e-3 * std::pow(r, n) * std::cos(std::numbers::pi * n / 2.0); }));
}

TEST(OscillationWatch, GrowthTooSlowOverTheBlocksDoesNotFire) {
  // mu = 2.005: (mu/2)^32 = 1.083 over four blocks, below the watch's 1.25; left to the speed bound.
  const double r = std::sqrt(1.0025);
  OscillationWatch watch(0.5, 4);
  EXPECT_FALSE(feed(watch, 4000, [&](int n) { return 0.4 * std::pow(r, n) * std::cos(std::numbers::pi * n / 2.0); }));
}

TEST(OscillationWatch, SaturatedOscillationIsStoppedByTheStandingRuleAndAJoltIsNot) {
  // Period-4 mode that jumps to amplitude 6 within a block and stays (as the 3D sector's fluid
  // CFL 0.21 run did): sqrt(2) x 6 = 8.5 m/s per block, level, so the growth rule never fires.
  const auto saturated = [](int n) { return (n < 40 ? 0.01 : 6.0) * std::cos(std::numbers::pi * n / 2.0); };
  OscillationWatch growth_only(0.5, 12);
  EXPECT_FALSE(feed(growth_only, 100 * kBlock, saturated));
  OscillationWatch standing(0.5, 12, 5.0, 8);
  const auto fired = feed(standing, 100 * kBlock, saturated);
  ASSERT_TRUE(fired);
  EXPECT_TRUE(fired->alarm.standing);
  EXPECT_EQ(fired->alarm.blocks, 8);
  EXPECT_NEAR(fired->alarm.oscillation, std::sqrt(2.0) * 6.0, 1e-12);
  // Block k holds windows 2 + 16k ... 17 + 16k. Block 2 (windows 34-49) takes the jump at 40
  // (RMS 6.9 m/s): the first at or above 5 m/s; the watch fires at the end of block 9, the 8th.
  EXPECT_EQ(fired->window, 2 + 10 * kBlock - 1);
  // A jolt at the same level lasting 7 blocks (the 2D closing's chatter grew for at most 7)
  // passes, and so does the saturated mode with the rule off.
  OscillationWatch jolt(0.5, 12, 5.0, 8);
  EXPECT_FALSE(feed(jolt, 100 * kBlock, [](int n) {
    return (n >= 2 && n < 2 + 7 * kBlock ? 6.0 : 0.0) * std::cos(std::numbers::pi * n / 2.0);
  }));
  OscillationWatch off(0.5, 12, 0.0, 8);
  EXPECT_FALSE(feed(off, 100 * kBlock, saturated));
}

}  // namespace
}  // namespace valvefsi::coupler
