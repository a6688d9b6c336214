// fluid_sph: runs the fluid part of a case on its own (rigid walls, pressure plates, probes).
//   fluid_sph --case cases/tube.textproto [--output DIR] [--threads N]
#include <omp.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <filesystem>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/fluid/case_setup.hpp"
#include "valvefsi/fluid/output.hpp"

namespace {

using namespace valvefsi::fluid;
using Clock = std::chrono::steady_clock;

std::string hms(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  return fmt::format("{:02d}:{:02d}:{:02d}", s / 3600, (s / 60) % 60, s % 60);
}

template <int D>
int run(const valvefsi::cases::Case& c, const std::filesystem::path& case_file, const std::filesystem::path& output) {
  auto setup = fluid_setup_from_case<D>(c, case_file);
  const ProbeSet<D> probes = setup.probes;
  const std::size_t plate_count = setup.plates.size();
  FluidSolver<D> solver = make_solver<D>(std::move(setup));
  solver.compute_body_forces_every_step(probes.wall_forces);
  const auto& p = solver.particles();
  spdlog::info("fluid_sph: {}D, {} fluid + {} wall particles, dp = {} m, h = {} m, c0 = {} m/s, {} plate(s), {} OpenMP thread(s)", D,
               p.count(Kind::fluid), p.count(Kind::wall), solver.settings().particle_spacing, solver.settings().smoothing_length(),
               solver.settings().sound_speed, plate_count, omp_get_max_threads());

  SnapshotWriter<D> snapshots(output);
  SeriesWriter series(output / "fluid_probes.h5");
  for (const auto& q : probes.pressure_points) series.add_column("pressure/" + q.name);
  for (const auto& q : probes.flow_planes) series.add_column("flow_rate/" + q.name);
  for (const auto& q : probes.velocity_planes) series.add_column("max_velocity/" + q.name);
  if (probes.wall_forces || plate_count > 0) series.add_column("wall_force/fixed_walls", D);
  for (std::size_t k = 0; k < plate_count; ++k) {
    series.add_column(fmt::format("plate_{}/force", k), D);
    series.add_column(fmt::format("plate_{}/displacement", k));
    series.add_column(fmt::format("plate_{}/velocity", k));
  }
  series.add_column("lost_particles");
  auto sample = [&] {
    std::vector<double> row;
    for (const auto& q : probes.pressure_points) row.push_back(pressure_at<D>(solver, q.position));
    for (const auto& q : probes.flow_planes) row.push_back(flow_rate<D>(solver, q.plane));
    for (const auto& q : probes.velocity_planes) row.push_back(max_speed_on_plane<D>(solver, q.plane));
    if (probes.wall_forces || plate_count > 0)
      for (int d = 0; d < D; ++d) row.push_back(solver.body_forces()[0][d]);
    for (std::size_t k = 0; k < plate_count; ++k) {
      for (int d = 0; d < D; ++d) row.push_back(solver.body_forces()[k + 1][d]);
      row.push_back(solver.plates()[k].displacement);
      row.push_back(solver.plates()[k].velocity);
    }
    row.push_back(static_cast<double>(solver.lost_count()));
    series.append(solver.time(), row);
  };

  const double end_time = c.run().end_time();
  const double snapshot_interval = c.run().snapshot_interval();
  const double series_interval = c.run().series_interval();
  double next_snapshot = 0.0, next_sample = 0.0;
  const auto start = Clock::now();
  auto last_report = start;
  const long first_step = solver.step_count();
  while (true) {
    if (snapshot_interval > 0 && solver.time() >= next_snapshot * (1 - 1e-12)) {
      snapshots.write(solver);
      next_snapshot += snapshot_interval;
    }
    if (solver.time() >= next_sample * (1 - 1e-12)) {
      sample();
      next_sample += series_interval;
      if (series.samples() % 200 == 0) series.flush();
    }
    if (solver.time() >= end_time * (1 - 1e-12)) break;
    double target = std::min(end_time, series_interval > 0 ? next_sample : end_time);
    if (snapshot_interval > 0) target = std::min(target, next_snapshot);
    if (series_interval <= 0) {
      solver.step();
    } else {
      solver.advance_to(target);
    }
    const auto now = Clock::now();
    if (std::chrono::duration<double>(now - last_report).count() > 10.0) {
      last_report = now;
      const double elapsed = std::chrono::duration<double>(now - start).count();
      const double eta = elapsed / std::max(solver.time(), 1e-30) * (end_time - solver.time());
      spdlog::info("t = {:.5f} / {} s, step {}, dt = {:.3e} s, lost {}, elapsed {}, left ~{}", solver.time(), end_time,
                   solver.step_count(), solver.time_step(), solver.lost_count(), hms(elapsed), hms(eta));
    }
  }
  series.flush();
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  const double updates = static_cast<double>(p.size()) * static_cast<double>(solver.step_count() - first_step);
  spdlog::info("fluid_sph: done, t = {} s in {} steps, wall time {:.1f} s ({:.3g} particle updates/s), {} particle(s) lost ({} of them by density out of range), output in {}",
               solver.time(), solver.step_count(), wall, updates / std::max(wall, 1e-9), solver.lost_count(),
               solver.density_out_of_range_count(), output.string());
  return solver.lost_count() == 0 ? 0 : 3;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"fluid_sph: weakly compressible SPH blood flow with rigid walls and pressure plates"};
  std::string case_path, output_dir;
  int threads = 0;
  app.add_option("--case", case_path, "case file (protobuf text format, message valvefsi.cases.Case)")->required();
  app.add_option("--output", output_dir, "output folder (default: the case's run.output_dir)");
  app.add_option("--threads", threads, "OpenMP threads (default: OMP_NUM_THREADS or all cores)")->check(CLI::Range(1, 4096));
  CLI11_PARSE(app, argc, argv);
  if (threads > 0) omp_set_num_threads(threads);
  try {
    const valvefsi::cases::Case c = valvefsi::load_case(case_path);
    const std::filesystem::path output = output_dir.empty() ? std::filesystem::path(c.run().output_dir()) : std::filesystem::path(output_dir);
    return c.run().dimension() == 2 ? run<2>(c, case_path, output) : run<3>(c, case_path, output);
  } catch (const valvefsi::CaseError& e) {
    spdlog::error("{}", e.what());
    return 2;
  } catch (const std::exception& e) {
    spdlog::error("fluid_sph: {}", e.what());
    return 1;
  }
}
