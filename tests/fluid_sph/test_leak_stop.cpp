// Leaks stop the run (FluidSettings::max_leak_fraction): a water column collapses against a
// fixed plane (the test double of an immersed surface) that blocks the pairs across it but,
// with put_back = false, does not put crossing particles back, so the surge front goes through
// it and every crossing counts as a leak. With the limit at 0 the solver stops at the first
// leak with a LeakLimitExceeded that names the count, the time, the limit and a particle near
// the surface, leaving a finite state;
// a limit of 2 % (4 of 200 particles) stops the same run later, after more than 4 leaks; with
// put-backs it never stops.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "plane_surface.hpp"
#include "valvefsi/fluid/fluid_solver.hpp"
#include "valvefsi/fluid/geometry.hpp"

namespace valvefsi::fluid {
namespace {

using testing::PlaneSurface;

struct Outcome {
  std::string message;  // empty: no stop
  double time = 0;
  std::size_t leaks = 0, corrections = 0, fluid = 0;
  bool finite = true;
};

Outcome collapse_against_plane(double max_leak_fraction, bool put_back) {
  FluidSettings<2> s;
  s.particle_spacing = 0.02;
  s.kernel = KernelType::wendland_c2;
  s.rest_density = 1000.0;
  s.dynamic_viscosity = 1e-3;
  s.artificial_viscosity = 0.02;
  s.gravity = {0.0, -9.81};
  s.sound_speed = 20.0 * std::sqrt(9.81 * 0.4);
  s.max_leak_fraction = max_leak_fraction;
  s.domain_lower = {-0.2, -0.2};
  s.domain_upper = {1.2, 1.0};
  SceneGeometry<2> scene;
  scene.walls.push_back(container_box<2>({0.0, 0.0}, {1.0, 1e9}));
  scene.fluid.push_back({{0.0, 0.0}, {0.2, 0.4}, {}, {}});  // 200 particles
  auto surface = std::make_unique<PlaneSurface<2>>(0.35, 2.0 * s.support_radius());
  surface->put_back = put_back;
  const PlaneSurface<2>* plane = surface.get();
  FluidSolver<2> solver(s, fill_particles(scene, s), {}, std::move(surface));
  Outcome out;
  out.fluid = solver.particles().count(Kind::fluid);
  try {
    solver.advance_to(0.6);  // the front reaches x = 0.35 at ~0.1 s
  } catch (const LeakLimitExceeded& e) {
    out.message = e.what();
  }
  out.time = solver.time();
  out.leaks = plane->counters().leaks;
  out.corrections = plane->counters().corrections;
  const auto& p = solver.particles();
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int d = 0; d < 2; ++d) out.finite = out.finite && std::isfinite(p.position[d][i]) && std::isfinite(p.velocity[d][i]);
  std::printf("limit %g, put back %d: %s at t = %.4f s, %zu leaks, %zu put back, %zu fluid particles\n", max_leak_fraction,
              put_back ? 1 : 0, out.message.empty() ? "ran" : "stopped", out.time, out.leaks, out.corrections, out.fluid);
  return out;
}

TEST(LeakStop, ALimitOfZeroStopsAtTheFirstLeakAndSaysWhereAndWhatToChange) {
  const Outcome out = collapse_against_plane(0.0, false);
  ASSERT_FALSE(out.message.empty()) << "the surge went through the plane without a stop";
  EXPECT_GE(out.leaks, 1u);
  EXPECT_LT(out.time, 0.6);
  EXPECT_TRUE(out.finite);
  std::printf("%s\n", out.message.c_str());
  EXPECT_NE(out.message.find(std::to_string(out.leaks) + " particle(s) found on the wrong side"), std::string::npos) << out.message;
  EXPECT_NE(out.message.find("fluid.max_leak_fraction = 0 of the " + std::to_string(out.fluid) + " fluid particles (0 allowed"),
            std::string::npos) << out.message;
  EXPECT_NE(out.message.find("the fastest fluid particle near the surface is particle"), std::string::npos) << out.message;
  EXPECT_NE(out.message.find("raise fluid.max_leak_fraction"), std::string::npos) << out.message;
}

TEST(LeakStop, AFractionLetsAFewLeaksPassAndStillStopsAPorousSurface) {
  const Outcome first = collapse_against_plane(0.0, false);
  const Outcome later = collapse_against_plane(0.02, false);  // 4 of 200 particles allowed
  ASSERT_FALSE(later.message.empty());
  EXPECT_EQ(later.leaks > 4u, true) << later.leaks;
  EXPECT_GE(later.time, first.time);
  const Outcome held = collapse_against_plane(0.0, true);  // put back: no leak, no stop
  EXPECT_TRUE(held.message.empty()) << held.message;
  EXPECT_EQ(held.leaks, 0u);
  EXPECT_GT(held.corrections, 0u);
  EXPECT_DOUBLE_EQ(held.time, 0.6);
}

}  // namespace
}  // namespace valvefsi::fluid
