// The fluid's loads on a thin wall are summed in an order fixed by the particles' indices
// (OrderedNodeLoads), so a run on two threads is the run on one, bit for bit, step by step, in 2D
// and 3D. Per-thread sums (the former way) made the two differ in the last bit from the first
// step, and a coupled run's leaflet then depended on the fluid's thread count.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>

#include "valvefsi/fluid/thin_wall/scenes_2d.hpp"
#include "valvefsi/fluid/thin_wall/scenes_3d.hpp"
#include "valvefsi/fluid/thin_wall/solver_run_2d.hpp"
#include "valvefsi/fluid/thin_wall/solver_run_3d.hpp"

namespace valvefsi::fluid::thin_wall {
namespace {

template <int D>
bool same_particles(const Particles<D>& a, const Particles<D>& b) {
  if (a.size() != b.size()) return false;
  for (int d = 0; d < D; ++d)
    if (a.position[d] != b.position[d] || a.velocity[d] != b.velocity[d]) return false;
  return a.density_excess == b.density_excess;
}

// Runs `one` on one thread and `two` on two, step by step, and asserts the wall's loads and the
// particles equal after every step.
template <class Run, class Loads>
void lockstep(Run& one, Run& two, int steps, const Loads& loads_of) {
  for (int step = 0; step < steps; ++step) {
    omp_set_num_threads(1);
    one.step();
    omp_set_num_threads(2);
    two.step();
    ASSERT_EQ(loads_of(one), loads_of(two)) << "the wall's loads differ at step " << step;
    ASSERT_TRUE(same_particles(one.particles(), two.particles())) << "the particles differ at step " << step;
  }
  omp_set_num_threads(1);
}

// A 2D wall standing 0.1 m above the floor between two water levels (flow under its free end).
TEST(ThinWallThreads, TwoDimensionalWallAboveAGapOneAndTwoThreadsGiveTheSameRun) {
  ThinWallSolverRun2D one(two_level_tank(0.025, 1.0, 0.5, 0.1));
  ThinWallSolverRun2D two(two_level_tank(0.025, 1.0, 0.5, 0.1));
  lockstep(one, two, 200, [](const ThinWallSolverRun2D& flow) {
    std::vector<Vec2> f;
    for (const auto& m : flow.wall_model().markers().markers()) f.push_back(m.force);
    return f;
  });
  EXPECT_GT(std::abs(one.wall_force()[0]), 100.0);  // the higher left level pushes the wall (N/m)
}

// A 3D membrane above a gap, ending on mirror planes (the sector's leaflet's images).
TEST(ThinWallThreads, ThreeDimensionalMembraneAboveAGapOneAndTwoThreadsGiveTheSameRun) {
  ThinWallSolverRun3D one(two_level_tank_3d(0.025, 0.5, 0.25, 0.15, 0.1, true));
  ThinWallSolverRun3D two(two_level_tank_3d(0.025, 0.5, 0.25, 0.15, 0.1, true));
  lockstep(one, two, 100, [](const ThinWallSolverRun3D& flow) { return flow.model().raw_node_forces(); });
  EXPECT_GT(std::abs(one.wall_force()[0]), 10.0);  // the higher left level pushes the membrane (N)
}

}  // namespace
}  // namespace valvefsi::fluid::thin_wall
