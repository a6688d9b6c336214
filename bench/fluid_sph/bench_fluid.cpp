// Particle updates per second (particles x steps / wall second) of the fluid solver on the
// 2D dam break at dp = 0.01 m (about 21k particles) and on a 3D tank of 100k particles, with
// 1 and 2 OpenMP threads. Each benchmark iteration is a fixed number of steps after the
// set-up; the yardstick (DualSPHysics 5.4, 2 threads) is about 1.6 M updates/s.
// BM_DamBreak2D_SurfaceLine adds an immersed surface (a vertical line through the column that
// flags the particles within a support as near and is asked about their pairs, but blocks
// none): the cost of the filtered pair path where a leaflet is.
// BM_SectorCoarse3D: the fluid of the coarse valve sector case.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cmath>
#include <memory>
#include <vector>

#include <filesystem>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/fluid/case_setup.hpp"
#include "valvefsi/fluid/immersed_surface.hpp"
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

// x = x0, flags particles within `near` of it, blocks nothing, adds nothing.
class SurfaceLine final : public ImmersedSurfaceModel<2> {
 public:
  SurfaceLine(double x0, double near) : x0_(x0), near_(near) {}
  void set_window_target(double, std::span<const Vec<2>>, std::span<const Vec<2>>) override {}
  void move_to(double) override {}
  double max_node_speed() const override { return 0.0; }
  void begin_step(const Particles<2>&) override {}
  void correct_crossings(Particles<2>&) override {}
  void classify(const Particles<2>& p) override {
    flags_.resize(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) flags_[i] = std::abs(p.position[0][i] - x0_) < near_;
  }
  bool near_surface(std::size_t i) const override { return flags_[i] != 0; }
  bool blocked(std::uint32_t a, std::uint32_t b, const Particles<2>& p) const override {
    return (p.position[0][a] < x0_) != (p.position[0][b] < x0_) && p.position[1][a] > 1e9;  // never
  }
  void update_surface_states(const Particles<2>&, const CellGrid<2>&) override {}
  void add_surface_rates(Particles<2>&) override {}
  bool accept_shift(const Particles<2>&, std::size_t, const Vec<2>&) override { return true; }
  std::size_t node_count() const override { return 1; }
  void node_forces(std::span<Vec<2>> forces) const override { forces[0] = Vec<2>{}; }
  ImmersedSurfaceCounters counters() const override { return {}; }
  void save_checkpoint() override {}
  void restore_checkpoint() override {}

 private:
  double x0_, near_;
  std::vector<char> flags_;
};

void BM_DamBreak2D_SurfaceLine(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(0)));
  auto db = dam_break_2d(0.01);
  FluidSolver<2> solver(db.settings, fill_particles(db.scene, db.settings), {},
                        std::make_unique<SurfaceLine>(0.5, db.settings.support_radius()));
  run_steps(state, solver, 200);
}
BENCHMARK(BM_DamBreak2D_SurfaceLine)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Tank3D_100k(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(0)));
  auto tank = still_tank_3d(100000);
  FluidSolver<3> solver(tank.settings, fill_particles(tank.scene, tank.settings));
  run_steps(state, solver, 10);
}
BENCHMARK(BM_Tank3D_100k)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// The fluid of the coarse 1/6 valve sector (cases/fsi-mhgo-sector-coarse.textproto, standalone:
// 56.6k fluid + 31.9k wall particles + ~35k mirror images, cubic spline, two plates, wall loads
// every step as its probes ask): the 3D case the cycle-time targets are about.
void BM_SectorCoarse3D(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(0)));
  const std::filesystem::path case_file = VALVEFSI_SOURCE_DIR "/cases/fsi-mhgo-sector-coarse.textproto";
  const cases::Case c = load_case(case_file);
  auto setup = fluid_setup_from_case<3>(c, case_file);
  const bool wall_forces = setup.probes.wall_forces;
  FluidSolver<3> solver = make_solver<3>(std::move(setup));
  solver.compute_body_forces_every_step(wall_forces);
  run_steps(state, solver, 10);
}
BENCHMARK(BM_SectorCoarse3D)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace valvefsi::fluid

BENCHMARK_MAIN();
