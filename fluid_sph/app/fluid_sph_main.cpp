// fluid_sph: the fluid part of a case, standalone (rigid walls, pressure plates, probes) or as
// the fluid participant of a coupled run.
//   fluid_sph --case CASE [--output DIR] [--threads N] [--coupled | --standalone]
// Coupled when the launcher set VALVEFSI_COUPLER_ENDPOINT (scripts/run_case.py does) or with
// --coupled; --standalone runs alone whatever the environment says. Under mpirun -np N the
// fluid is split into N slabs along its last axis (docs/fluid_sph.md, "MPI").
#include <omp.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdlib>
#include <filesystem>

#include "mpi_world.hpp"
#include "participant_mode.hpp"
#include "run_output.hpp"
#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/coupling/endpoint.hpp"
#include "valvefsi/fluid/case_setup.hpp"

namespace {

using namespace valvefsi::fluid;

template <int D>
int run_standalone(const valvefsi::cases::Case& c, const std::filesystem::path& case_file, const std::filesystem::path& output) {
  auto setup = fluid_setup_from_case<D>(c, case_file);
  const ProbeSet<D> probes = setup.probes;
  const std::size_t plate_count = setup.plates.size();
  FluidSolver<D> solver = make_solver<D>(std::move(setup));
  const app::MpiWorld world = app::mpi_world();
  if (world.split()) solver.decompose(MPI_COMM_WORLD);
  solver.compute_body_forces_every_step(probes.wall_forces);
  const std::size_t fluid_count = app::count_over_ranks(solver, Kind::fluid);
  const std::size_t wall_count = app::count_over_ranks(solver, Kind::wall);
  spdlog::info("fluid_sph: {}D, {} fluid + {} wall particles, dp = {} m, h = {} m, c0 = {} m/s, {} plate(s), {} OpenMP thread(s) x {} MPI rank(s)",
               D, fluid_count, wall_count, solver.settings().particle_spacing, solver.settings().smoothing_length(),
               solver.settings().sound_speed, plate_count, omp_get_max_threads(), world.size);

  const double end_time = c.run().end_time();
  app::RunOutput<D> run_output(probes, plate_count, false, output, end_time, c.run().snapshot_interval(),
                               c.run().series_interval(), world.root());
  const long first_step = solver.step_count();
  try {
    while (true) {
      run_output.write_due(solver);
      if (solver.time() >= end_time * (1 - 1e-12)) break;
      if (c.run().series_interval() <= 0) {
        solver.step();
      } else {
        solver.advance_to(run_output.next_due());
      }
    }
  } catch (const FluidStop&) {
    run_output.write_last_state(solver);  // every rank sees the collapse (the step is common)
    throw;
  }
  run_output.flush();
  const double wall = run_output.elapsed();
  const double updates = app::particles_over_ranks(solver) * static_cast<double>(solver.step_count() - first_step);
  spdlog::info("fluid_sph: done, t = {} s in {} steps, wall time {:.1f} s ({:.3g} particle updates/s), {} particle(s) lost ({} of them by density out of range), output in {}",
               solver.time(), solver.step_count(), wall, updates / std::max(wall, 1e-9), solver.lost_count(),
               solver.density_out_of_range_count(), output.string());
  return solver.lost_count() == 0 ? 0 : 3;
}

}  // namespace

int run(int argc, char** argv) {
  CLI::App app{"fluid_sph: weakly compressible SPH blood flow with rigid walls and pressure plates"};
  std::string case_path, output_dir;
  int threads = 0;
  bool coupled = false, standalone = false;
  app.add_option("--case", case_path, "case file (protobuf text format, message valvefsi.cases.Case)")->required();
  app.add_option("--output", output_dir, "output folder (default: the case's run.output_dir)");
  app.add_option("--threads", threads, "OpenMP threads (default: OMP_NUM_THREADS or all cores)")->check(CLI::Range(1, 4096));
  auto* coupled_flag = app.add_flag("--coupled", coupled, "take part in a coupled run (default when VALVEFSI_COUPLER_ENDPOINT is set)");
  app.add_flag("--standalone", standalone, "run alone even if VALVEFSI_COUPLER_ENDPOINT is set")->excludes(coupled_flag);
  CLI11_PARSE(app, argc, argv);
  if (threads > 0) omp_set_num_threads(threads);
  if (!standalone && std::getenv(valvefsi::coupling::kEndpointEnvironmentVariable) != nullptr) coupled = true;
  try {
    const valvefsi::cases::Case c = valvefsi::load_case(case_path);
    const std::filesystem::path output = output_dir.empty() ? std::filesystem::path(c.run().output_dir()) : std::filesystem::path(output_dir);
    if (coupled) return app::run_participant(c, case_path, output);
    return c.run().dimension() == 2 ? run_standalone<2>(c, case_path, output) : run_standalone<3>(c, case_path, output);
  } catch (const valvefsi::CaseError& e) {
    spdlog::error("{}", e.what());
    return 2;
  } catch (const std::exception& e) {
    spdlog::error("fluid_sph: {}", e.what());
    return 1;
  }
}

int main(int argc, char** argv) {
  // MPI only under a launcher; a rank that fails takes the others down (they would wait on it).
  const bool mpi = app::started_by_mpi_launcher();
  if (mpi) {
    // Ranks that wait yield the core instead of spinning (the machine is shared, as with
    // OMP_WAIT_POLICY=passive); an explicit setting in the environment wins.
    setenv("OMPI_MCA_mpi_yield_when_idle", "1", 0);
    int provided = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    if (!app::mpi_world().root()) spdlog::set_level(spdlog::level::warn);
  }
  const int code = run(argc, argv);
  if (mpi) {
    if (code != 0 && app::mpi_world().split()) MPI_Abort(MPI_COMM_WORLD, code);
    MPI_Finalize();
  }
  return code;
}
