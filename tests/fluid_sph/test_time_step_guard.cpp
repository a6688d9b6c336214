// A collapsing time step stops the run with a diagnosis instead of creeping on: a water block
// thrown at 20 times its sound speed has an acoustic step cfl h / (c0 + v) 21 times below the
// one at rest. And the coupling window a fluid proposes to hold whole steps.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "valvefsi/fluid/coupling_window.hpp"
#include "valvefsi/fluid/fluid_solver.hpp"
#include "valvefsi/fluid/geometry.hpp"

namespace valvefsi::fluid {
namespace {

FluidSettings<2> column_settings(double ratio) {
  FluidSettings<2> s;
  s.particle_spacing = 0.05;
  s.rest_density = 1000.0;
  s.dynamic_viscosity = 0.0;
  s.gravity = {0.0, 0.0};
  s.sound_speed = 60.0;
  s.domain_lower = {-0.5, -0.5};
  s.domain_upper = {1.5, 2.0};
  s.min_time_step_ratio = ratio;
  return s;
}

std::string run_steps(double speed, double ratio) {
  const auto s = column_settings(ratio);
  SceneGeometry<2> scene;
  scene.walls.push_back(container_box<2>({0.0, 0.0}, {1.0, 1e9}));
  scene.fluid.push_back({{0.2, 0.2}, {0.8, 0.8}, [speed](const Vec<2>&) { return Vec<2>{speed, 0.0}; }, {}});
  try {
    FluidSolver<2> solver(s, fill_particles(scene, s));
    for (int i = 0; i < 3; ++i) solver.step();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return {};
}

TEST(TimeStepGuard, CollapseStopsTheRunAndSaysWhy) {
  const std::string message = run_steps(1200.0, 0.1);
  ASSERT_FALSE(message.empty()) << "a step of 1/21 of the acoustic one passed a 0.1 guard";
  EXPECT_NE(message.find("time step collapsed"), std::string::npos) << message;
  EXPECT_NE(message.find("largest fluid speed 1.2e+03 m/s"), std::string::npos) << message;
  EXPECT_NE(message.find("min_time_step_ratio"), std::string::npos) << message;
  // Which limit, and where: the block moves at 1200 m/s, so the acoustic limit set the step and
  // the fastest particle is one of the block's (inside 0.2..0.8 m, at rest density or near it).
  EXPECT_NE(message.find("set by the acoustic limit"), std::string::npos) << message;
  EXPECT_NE(message.find("largest speed 1.2e+03 m/s at particle"), std::string::npos) << message;
  EXPECT_NE(message.find("density"), std::string::npos) << message;
}

TEST(TimeStepGuard, AStepAboveTheGuardRuns) {
  EXPECT_EQ(run_steps(1200.0, 0.03), "");  // 1/21 = 0.048 of the step at rest
  EXPECT_EQ(run_steps(0.0, 0.9), "");
}

// The 3D sector's diastole: a 10.53 us window and stable steps of 5.1 us cost 3 steps per
// window (5.1, 5.1, 0.33); fitted, 2 steps of 0.97 x 5.1 us.
TEST(CouplingWindowFit, ProposesTheLargestWholeNumberOfShrunkSteps) {
  EXPECT_NEAR(fitted_coupling_window(5.1e-6, 10.53e-6), 2 * 0.97 * 5.1e-6, 1e-18);
  EXPECT_NEAR(fitted_coupling_window(3.0e-6, 10.53e-6), 3 * 0.97 * 3.0e-6, 1e-18);  // 4 steps -> 3
  EXPECT_NEAR(fitted_coupling_window(8.0e-6, 10.53e-6), 0.97 * 8.0e-6, 1e-18);      // 2 steps -> 1
}

TEST(CouplingWindowFit, KeepsTheCaseWindowWhenFittingSavesLittleOrNothing) {
  // 2 steps of 5.265 us fill the window: fitting would save 0.04 % of the steps.
  EXPECT_EQ(fitted_coupling_window(5.43e-6, 10.53e-6), 0.0);
  EXPECT_EQ(fitted_coupling_window(20e-6, 10.53e-6), 0.0);  // one clipped step per window
  EXPECT_EQ(fitted_coupling_window(0.0, 10.53e-6), 0.0);
  EXPECT_EQ(fitted_coupling_window(5e-6, 0.0), 0.0);
  // 4.9 us: 3 steps of 3.51 us vs 2 of 4.753 us, a 35 % saving; demanded above 40 %, none.
  EXPECT_GT(fitted_coupling_window(4.9e-6, 10.53e-6), 0.0);
  EXPECT_EQ(fitted_coupling_window(4.9e-6, 10.53e-6, CouplingWindowFit{0.97, 0.4}), 0.0);
}

// The fitter learns its margin: a window that took more steps than planned (the step fell
// within it) shrinks the margin by 0.02; a window that kept to its plan grows it by 0.002.
TEST(CouplingWindowFit, FitterShrinksItsMarginWhenAWindowOverruns) {
  CouplingWindowFitter fitter(10.53e-6);
  EXPECT_NEAR(fitter.propose(5.1e-6, 3), 2 * 0.97 * 5.1e-6, 1e-18);  // no plan yet: margin kept
  EXPECT_NEAR(fitter.propose(5.1e-6, 3), 2 * 0.95 * 5.1e-6, 1e-18);  // 3 steps for 2 planned
  EXPECT_NEAR(fitter.propose(5.1e-6, 2), 2 * 0.952 * 5.1e-6, 1e-18);  // kept to the plan
  EXPECT_EQ(fitter.overruns(), 1);
  EXPECT_DOUBLE_EQ(fitter.mean_steps_per_window(), 8.0 / 3.0);
  for (int i = 0; i < 20; ++i) fitter.propose(5.1e-6, 3);  // overruns throughout: the floor
  EXPECT_DOUBLE_EQ(fitter.margin(), 0.8);
  for (int i = 0; i < 200; ++i) fitter.propose(5.1e-6, 2);  // never: the ceiling
  EXPECT_DOUBLE_EQ(fitter.margin(), 0.99);
}

}  // namespace
}  // namespace valvefsi::fluid
