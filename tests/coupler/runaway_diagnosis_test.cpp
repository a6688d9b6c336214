// The diagnosis of an interface runaway (InterfaceHistory, diagnose_runaway, explain_runaway) on
// histories with known answers: a sine's equivalent period is its period, exactly; the
// serial-explicit piston's growing period-4 mode is window-scale and names the added-mass
// remedies; a smooth ringing fed by the fluid's loads (the 3D closed valve's kind, ~20 windows per
// period) is not added mass and names the fluid's side; the same ringing without the fluid's work
// names the solid; the loads' work is summed block by block, back from the last window.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "valvefsi/coupler/runaway_diagnosis.hpp"

namespace valvefsi::coupler {
namespace {

constexpr int kBlock = InterfaceHistory::kWindows;

// Two nodes: node 0 at rest, node 1 moving in the x-y plane at speed v(n) along a fixed direction.
Eigen::Matrix3Xd velocities(double v) {
  Eigen::Matrix3Xd m = Eigen::Matrix3Xd::Zero(3, 2);
  m(0, 1) = 0.6 * v;
  m(1, 1) = 0.8 * v;
  return m;
}

// By default the fluid gave 90 % of the loads' work (the rest created by the coupling's lag).
template <class V, class W>
InterfaceHistory feed(int windows, V v, W work, double fluid_share = 0.9) {
  InterfaceHistory history;
  for (int n = 0; n < windows; ++n) history.update(velocities(v(n)), work(n), fluid_share * work(n));
  return history;
}

double sine_period(double period, int windows) {
  const auto history = feed(
      windows, [&](int n) { return 2.0 * std::sin(2.0 * std::numbers::pi * n / period + 0.3); },
      [](int) { return 0.0; });
  const auto d = diagnose_runaway(history, 1);
  EXPECT_NEAR(d.velocity_period, d.period_windows, 1e-9 * period);  // the jumps of a sine are a sine
  return d.period_windows;
}

bool contains(const std::string& text, const std::string& words) { return text.find(words) != std::string::npos; }

TEST(RunawayDiagnosis, TheEquivalentPeriodOfASineIsItsPeriod) {
  // d_n = -4 sin^2(pi / P) v_{n-1} for every n (and so for d's own jumps), so the ratio of the RMS
  // values is exact.
  for (double period : {2.5, 3.0, 4.0, 7.5, 8.5, 20.0, 50.0}) {
    EXPECT_NEAR(sine_period(period, 100), period, 1e-9 * period) << period;
  }
  // Fewer windows than a block: measured over what there is.
  EXPECT_NEAR(sine_period(20.0, 9), 20.0, 1e-9 * 20.0);
  // Alternation (P = 2: d = 4 v) and a node set moving within a window are as short as it gets;
  // a node at rest has no time scale.
  EXPECT_EQ(equivalent_period(4.0, 1.0), 2.0);
  EXPECT_EQ(equivalent_period(1.0, 0.0), 2.0);
  EXPECT_TRUE(std::isinf(equivalent_period(0.0, 0.0)));
}

TEST(RunawayDiagnosis, ThePeriodThatSeparatesWindowScaleFromSmoothIsTwelveWindows) {
  for (double period : {11.5, 12.5}) {
    const auto history = feed(
        40, [&](int n) { return std::sin(2.0 * std::numbers::pi * n / period); }, [](int) { return 1e-6; });
    const auto d = diagnose_runaway(history, 1);
    EXPECT_EQ(d.kind, period < kWindowScalePeriod ? RunawayDiagnosis::Kind::window_scale
                                                  : RunawayDiagnosis::Kind::smooth_fluid_work)
        << period;
  }
}

TEST(RunawayDiagnosis, AWindowScaleModeRidingOnTheLeafletsMotionShowsInTheJumps) {
  // 1.5 m/s over 200 windows plus a 0.05 m/s period-4 mode: the velocity's period says smooth
  // (the motion dominates v), the jumps' says window-scale (the mode dominates d).
  const auto history = feed(
      400,
      [](int n) { return 1.5 * std::sin(2.0 * std::numbers::pi * n / 200.0) + 0.05 * std::cos(std::numbers::pi * n / 2.0); },
      [](int) { return 1e-7; });
  const auto d = diagnose_runaway(history, 1);
  EXPECT_GT(d.velocity_period, kWindowScalePeriod);
  EXPECT_NEAR(d.period_windows, 4.0, 0.05);
  EXPECT_EQ(d.kind, RunawayDiagnosis::Kind::window_scale);
}

TEST(RunawayDiagnosis, TheExplicitPistonsGrowingModeIsWindowScaleAndNamesTheAddedMassRemedies) {
  // mu = 2.02: |z| = sqrt(mu / 2) per window, argument ~ pi / 2 (a period of 4 windows).
  const double r = std::sqrt(1.01);
  const auto history = feed(
      600, [&](int n) { return 1e-3 * std::pow(r, n) * std::cos(std::numbers::pi * n / 2.0); },
      [](int n) { return n % 2 ? 1e-7 : -0.5e-7; });
  const auto d = diagnose_runaway(history, 1);
  EXPECT_EQ(d.kind, RunawayDiagnosis::Kind::window_scale);
  EXPECT_EQ(d.jumps, kBlock);
  EXPECT_NEAR(d.period_windows, 4.0, 0.02);  // the growth shifts it from 4 by O(mu/2 - 1)
  const std::string explicit_text = explain_runaway(d, SchemeKind::serial_explicit);
  for (const char* words : {"grows at the window's scale", "added-mass instability", "smaller coupling.window_size",
                            "SERIAL_IMPLICIT", "heavier or thicker leaflet"}) {
    EXPECT_TRUE(contains(explicit_text, words)) << words << " not in: " << explicit_text;
  }
  EXPECT_FALSE(contains(explicit_text, "not the coupling's")) << explicit_text;
  const std::string implicit_text = explain_runaway(d, SchemeKind::serial_implicit);
  EXPECT_TRUE(contains(implicit_text, "implicit iterations did not hold it")) << implicit_text;
  EXPECT_FALSE(contains(implicit_text, "SERIAL_IMPLICIT")) << implicit_text;
}

// The 3D closed valve's failure (docs/fsi-3d.md): node speeds growing smoothly, ~20 windows per
// period (the interface power's period at 52 ms), 0.3/ms at 10.53 us windows for the energy.
constexpr double kRingingPeriod = 20.0;
constexpr double kAmplitudeGrowthPerWindow = 0.15e3 * 10.53e-6;
double ringing(int n) {
  return 0.5 * std::exp(kAmplitudeGrowthPerWindow * n) * std::sin(2.0 * std::numbers::pi * n / kRingingPeriod);
}

TEST(RunawayDiagnosis, ASmoothRingingFedByTheFluidIsNotAddedMassAndNamesTheFluidsSide) {
  auto work = [](int n) { return 2e-6 * std::exp(2.0 * kAmplitudeGrowthPerWindow * n) * (n % 3 ? 1.0 : -0.5); };
  const int windows = 5000;
  const auto history = feed(windows, ringing, work);
  const auto d = diagnose_runaway(history, 1);
  EXPECT_EQ(d.kind, RunawayDiagnosis::Kind::smooth_fluid_work);
  EXPECT_NEAR(d.period_windows, kRingingPeriod, 0.01 * kRingingPeriod);
  // The last four blocks of 16 windows, each summed, oldest first.
  ASSERT_EQ(d.block_work.size(), static_cast<std::size_t>(InterfaceHistory::kWorkBlocks));
  double net = 0.0;
  for (int b = 0; b < InterfaceHistory::kWorkBlocks; ++b) {
    double block = 0.0;
    for (int k = 0; k < kBlock; ++k) block += work(windows - (InterfaceHistory::kWorkBlocks - b) * kBlock + k);
    EXPECT_NEAR(d.block_work[b], block, 1e-12 * std::abs(block)) << b;
    net += block;
  }
  EXPECT_NEAR(d.net_work, net, 1e-12 * net);
  EXPECT_NEAR(d.created_work, 0.1 * net, 1e-9 * net);
  EXPECT_EQ(d.positive_blocks, 4);
  // Under either scheme (the closed valve grew as fast under IQN-ILS): the same cause.
  for (auto scheme : {SchemeKind::serial_explicit, SchemeKind::serial_implicit}) {
    const std::string text = explain_runaway(d, scheme);
    for (const char* words : {"grows smoothly over many windows", "not the coupling's added-mass instability",
                              "from the fluid's side", "tension", "background pressure", "fluid.cfl", "resolution", "c0",
                              "positive in 4 of them"}) {
      EXPECT_TRUE(contains(text, words)) << words << " not in: " << text;
    }
    for (const char* words : {"SERIAL_IMPLICIT", "smaller coupling.window_size", "heavier"}) {
      EXPECT_FALSE(contains(text, words)) << words << " in: " << text;
    }
  }
}

TEST(RunawayDiagnosis, ASmoothGrowthWithoutTheFluidsWorkNamesTheSolid) {
  const auto history = feed(400, ringing, [](int) { return -1e-6; });
  const auto d = diagnose_runaway(history, 1);
  EXPECT_EQ(d.kind, RunawayDiagnosis::Kind::smooth_no_fluid_work);
  EXPECT_NEAR(d.net_work, -64e-6, 1e-18);
  EXPECT_EQ(d.positive_blocks, 0);
  const std::string text = explain_runaway(d, SchemeKind::serial_explicit);
  for (const char* words : {"not the coupling's added-mass instability", "does not come in through the interface",
                            "solid.max_energy_balance_error"}) {
    EXPECT_TRUE(contains(text, words)) << words << " not in: " << text;
  }
  EXPECT_FALSE(contains(text, "tension")) << text;
}

TEST(RunawayDiagnosis, ASmoothGrowthFedByTheCouplingsLagNamesTheWindowAndTheFluidStep) {
  // The 2D valve at fluid CFL 0.2 (docs/coupling.md): the lag created 0.068 J, the fluid took
  // 0.064 J. Here the fluid takes half the loads' work back: the lag created 1.5 x it.
  const auto history = feed(400, ringing, [](int) { return 1e-6; }, -0.5);
  const auto d = diagnose_runaway(history, 1);
  EXPECT_EQ(d.kind, RunawayDiagnosis::Kind::smooth_coupling_lag);
  EXPECT_NEAR(d.created_work, 1.5 * 64e-6, 1e-18);
  const std::string text = explain_runaway(d, SchemeKind::serial_explicit);
  for (const char* words : {"not the coupling's added-mass mode", "created at the interface by the explicit coupling's lag",
                            "smaller coupling.window_size", "SERIAL_IMPLICIT", "fluid.cfl", "-3.2e-05 J the fluid gave"}) {
    EXPECT_TRUE(contains(text, words)) << words << " not in: " << text;
  }
  EXPECT_FALSE(contains(text, "tension")) << text;
}

TEST(RunawayDiagnosis, TheLoadsWorkIsSummedInBlocksBackFromTheLastWindow) {
  // w_n = n: after 20 windows the blocks are windows 0-3 (a part) and 4-19.
  const auto early = feed(20, [](int) { return 0.0; }, [](int n) { return static_cast<double>(n); });
  ASSERT_EQ(early.block_work().size(), 2u);
  EXPECT_EQ(early.block_work()[0], 0.0 + 1 + 2 + 3);
  EXPECT_EQ(early.block_work()[1], (4.0 + 19.0) * 16 / 2);
  // After 70 windows: the last 64, windows 6-69, in four blocks.
  const auto late = feed(70, [](int) { return 0.0; }, [](int n) { return static_cast<double>(n); });
  const auto blocks = late.block_work();
  ASSERT_EQ(blocks.size(), 4u);
  for (int b = 0; b < 4; ++b) {
    const double first = 6 + 16 * b;
    EXPECT_EQ(blocks[b], (2 * first + 15) * 16 / 2) << b;
  }
}

TEST(RunawayDiagnosis, TooEarlyToMeasureKeepsTheSchemesRemedies) {
  // The jumps' period needs five windows.
  const auto history = feed(4, [](int n) { return 30.0 * n * n; }, [](int) { return 0.0; });
  const auto d = diagnose_runaway(history, 1);
  EXPECT_EQ(d.kind, RunawayDiagnosis::Kind::too_early);
  const std::string text = explain_runaway(d, SchemeKind::serial_explicit);
  EXPECT_TRUE(contains(text, "Too early")) << text;
  EXPECT_TRUE(contains(text, "SERIAL_IMPLICIT")) << text;
}

}  // namespace
}  // namespace valvefsi::coupler
