// Explicit steps of a pressurised MHGO leaflet-like plate (336 triangles, the size of the coarse
// valve sector): CPU time per step and simulated time per CPU second, with the element step
// estimate alone (arg 0) and calibrated by Lanczos every 2000 steps (arg 1). One thread.
#include <benchmark/benchmark.h>

#include "test_meshes.hpp"
#include "valvefsi/solid/shell_solver.hpp"

namespace {

using namespace valvefsi::solid;

void BM_MhgoPlateSteps(benchmark::State& state) {
  const Mesh mesh = testing::rectangular_plate(0.01, 0.007, 14, 12, 0.3e-3, false, 0.2);
  ShellModelOptions options;
  for (const char* side : {"left", "right", "bottom"}) {
    for (const auto n : mesh.node_sets.at(side)) options.fixed_nodes.push_back(n);
  }
  SolverOptions solver_options;
  solver_options.time_step_calibration_interval = state.range(0) != 0 ? 2000 : 0;
  ShellSolver solver(build_shell_model(mesh, options), Material{Mhgo{}}, solver_options);
  solver.set_pressure([](double t) { return std::min(1.0, t / 2e-3) * 1000.0; });  // ramp to 1 kPa
  solver.advance_window(2e-3);  // a loaded, stiffened state
  const std::int64_t first_step = solver.state().step;
  const double first_time = solver.state().time;
  for (auto _ : state) {
    solver.advance_window(solver.state().time + 2e-4);
    benchmark::DoNotOptimize(solver.state().position.data());
  }
  const auto steps = static_cast<double>(solver.state().step - first_step);
  state.counters["steps"] = steps;
  state.counters["dt_us"] = 1e6 * (solver.state().time - first_time) / steps;
  state.counters["steps_per_s"] = benchmark::Counter(steps, benchmark::Counter::kIsRate);
  state.SetLabel(mesh.triangles.size() == 336 ? "336 triangles" : "");
}

BENCHMARK(BM_MhgoPlateSteps)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
BENCHMARK_MAIN();
