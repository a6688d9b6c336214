// One implicit (generalized-alpha + Newton) step of a closed-valve-like state: the MHGO plate of
// solid_step_bench (336 triangles, the coarse sector's size, clamped on three sides) settled under
// 80 mmHg. Three figures, one thread: the element tangent alone (forward differences of each
// element's force), a 0.1 ms step that builds and factorises its tangent (SparseLU), and the same
// step with the tangent kept from the previous one (modified Newton's usual case once settled).
#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

#include "test_meshes.hpp"
#include "valvefsi/solid/shell_elements.hpp"
#include "valvefsi/solid/shell_solver.hpp"

namespace {

using namespace valvefsi::solid;

constexpr double kClosedPressure = 80.0 * 133.322387415;  // Pa
constexpr double kStep = 1e-4;                            // s

Mesh plate() { return testing::rectangular_plate(0.01, 0.007, 14, 12, 0.3e-3, false, 0.2); }

ShellModel plate_model() {
  const Mesh mesh = plate();
  ShellModelOptions options;
  for (const char* side : {"left", "right", "bottom"}) {
    for (const auto n : mesh.node_sets.at(side)) options.fixed_nodes.push_back(n);
  }
  return build_shell_model(mesh, options);
}

// The settled, pressurised state (implicit, 20 ms, mass damping 200/s), computed once (~15 s).
SolverOptions implicit_options() {
  SolverOptions o;
  o.time_integration = TimeIntegration::implicit_generalized_alpha;
  o.max_time_step = kStep;
  o.implicit_initial_step = kStep;
  o.mass_damping_per_s = 200.0;
  return o;
}

double pressure(double t) { return std::min(1.0, t / 2e-3) * kClosedPressure; }

const SolverState& settled_state() {
  static const SolverState settled = [] {
    ShellSolver solver(plate_model(), Material{Mhgo{}}, implicit_options());
    solver.set_pressure(pressure);
    solver.advance_window(20e-3);
    return solver.state();
  }();
  return settled;
}

void BM_ElementTangent(benchmark::State& state) {
  const SolverState& settled = settled_state();
  ShellElements elements(plate_model(), Material{Mhgo{}});
  std::vector<NodeBlock> blocks;
  for (auto _ : state) {
    elements.internal_force_tangent(settled.position, blocks);
    benchmark::DoNotOptimize(blocks.data());
  }
  state.counters["blocks"] = static_cast<double>(blocks.size());
}

// arg 1: the tangent is built and factorised at every step; arg 0: kept from the last step.
void BM_ImplicitStep(benchmark::State& state) {
  const SolverState& settled = settled_state();
  auto solver = std::make_unique<ShellSolver>(plate_model(), Material{Mhgo{}}, implicit_options());
  solver->set_pressure(pressure);
  const bool fresh = state.range(0) != 0;
  double iterations = 0;
  for (auto _ : state) {
    solver->restore(settled);
    if (fresh) solver->drop_kept_tangent();
    solver->advance_window(settled.time + kStep);
    iterations += solver->state().newton_iterations;
    benchmark::DoNotOptimize(solver->state().position.data());
  }
  state.counters["newton_iterations"] = iterations / static_cast<double>(state.iterations());
  state.counters["kinetic_J"] = settled.energy.kinetic;
  state.counters["strain_J"] = settled.energy.strain_energy;
  state.SetLabel(fresh ? "tangent built and factorised" : "tangent kept");
}

BENCHMARK(BM_ElementTangent)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ImplicitStep)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

}  // namespace
BENCHMARK_MAIN();
