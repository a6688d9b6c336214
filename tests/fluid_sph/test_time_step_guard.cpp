// A collapsing time step stops the run with a diagnosis instead of creeping on: a water block
// thrown at 20 times its sound speed has an acoustic step cfl h / (c0 + v) 21 times below the
// one at rest.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

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

}  // namespace
}  // namespace valvefsi::fluid
