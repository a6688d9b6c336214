// Particle updates per second (particles x steps / wall second) of the fluid solver on the
// 2D dam break at dp = 0.01 m (about 21k particles) and on a 3D tank of 100k particles, with
// 1 and 2 OpenMP threads. Each benchmark iteration is a fixed number of steps after the
// set-up; the yardstick (DualSPHysics 5.4, 2 threads) is about 1.6 M updates/s.
#include <benchmark/benchmark.h>
#include <omp.h>

#include "valvefsi/fluid/standard_scenes.hpp"

namespace valvefsi::fluid {
namespace {

template <int D>
void run_steps(benchmark::State& state, FluidSolver<D>& solver, int steps_per_iteration) {
  for (auto _ : state) {
    for (int k = 0; k < steps_per_iteration; ++k) solver.step();
  }
  const double updates = static_cast<double>(solver.particles().size()) * steps_per_iteration;
  state.counters["particles"] = static_cast<double>(solver.particles().size());
  state.counters["updates_per_s"] = benchmark::Counter(updates, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["sim_time_s"] = solver.time();
}

void BM_DamBreak2D(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(0)));
  auto db = dam_break_2d(0.01);
  FluidSolver<2> solver(db.settings, fill_particles(db.scene, db.settings));
  run_steps(state, solver, 200);
}
BENCHMARK(BM_DamBreak2D)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Tank3D_100k(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(0)));
  auto tank = still_tank_3d(100000);
  FluidSolver<3> solver(tank.settings, fill_particles(tank.scene, tank.settings));
  run_steps(state, solver, 10);
}
BENCHMARK(BM_Tank3D_100k)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace valvefsi::fluid

BENCHMARK_MAIN();
