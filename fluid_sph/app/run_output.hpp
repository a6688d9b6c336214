#pragma once
// What fluid_sph writes while it runs, shared by the standalone and the coupled mode: particle
// snapshots every run.snapshot_interval, the probe series (fluid_probes.h5) every
// run.series_interval, and a progress line every 10 s of wall time.
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "valvefsi/fluid/case_setup.hpp"
#include "valvefsi/fluid/mirror_group.hpp"
#include "valvefsi/fluid/output.hpp"

namespace valvefsi::fluid::app {

inline std::string hms(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  return fmt::format("{:02d}:{:02d}:{:02d}", s / 3600, (s / 60) % 60, s % 60);
}

template <int D>
class RunOutput {
 public:
  using Clock = std::chrono::steady_clock;

  // `root`: this process writes the files (rank 0 of a split run; the others only take part
  // in the collective probes and snapshot gathers).
  RunOutput(const ProbeSet<D>& probes, std::size_t plate_count, bool interface_columns, const std::filesystem::path& output,
            double end_time, double snapshot_interval, double series_interval, bool root = true)
      : probes_(probes), plate_count_(plate_count), interface_(interface_columns), root_(root), snapshots_(output, root),
        series_(output / "fluid_probes.h5"), end_time_(end_time), snapshot_interval_(snapshot_interval),
        series_interval_(series_interval), start_(Clock::now()), last_report_(start_) {
    for (const auto& q : probes.pressure_points) series_.add_column("pressure/" + q.name);
    for (const auto& q : probes.flow_planes) series_.add_column("flow_rate/" + q.name);
    for (const auto& q : probes.velocity_planes) series_.add_column("max_velocity/" + q.name);
    if (probes.wall_forces || plate_count > 0) series_.add_column("wall_force/fixed_walls", D);
    for (std::size_t k = 0; k < plate_count; ++k) {
      series_.add_column(fmt::format("plate_{}/force", k), D);
      series_.add_column(fmt::format("plate_{}/displacement", k));
      series_.add_column(fmt::format("plate_{}/velocity", k));
      // The gauge pressure driving the plate: prescribed + the common level of plates_never_pull.
      series_.add_column(fmt::format("plate_{}/drive_pressure", k));
    }
    series_.add_column("lost_particles");
    if (interface_) {
      // Sum of the fluid's force on the interface nodes (N; N/m in 2D), averaged over the last
      // coupling window, and the surface model's counters.
      series_.add_column("interface/force", D);
      series_.add_column("interface/corrections");
      series_.add_column("interface/leaks");
    }
  }

  // Writes whatever is due at the solver's current time. `interface_force`: the last window's
  // total force on the interface (ignored without interface columns).
  void write_due(const FluidSolver<D>& solver, const Vec<D>& interface_force = {}) {
    const double t = solver.time();
    if (std::isnan(first_time_)) {
      first_time_ = t;  // a restarted run's rate counts from its restart time
      // Copies of this fluid that make the whole (6 for a 1/6 sector): the analysis scales a
      // part's flows and forces with it (scripts/valve_scene/hemodynamics.py).
      series_.set_attribute("symmetry_factor", mirror_symmetry_factor(solver.settings().mirror_planes));
    }
    if (snapshot_interval_ > 0 && t >= next_snapshot_ * (1 - 1e-12)) {
      snapshots_.write(solver);
      while (next_snapshot_ <= t * (1 + 1e-12)) next_snapshot_ += snapshot_interval_;
    }
    if (t >= next_sample_ * (1 - 1e-12)) {
      sample(solver, interface_force);
      if (series_interval_ > 0)
        while (next_sample_ <= t * (1 + 1e-12)) next_sample_ += series_interval_;
      else
        next_sample_ = t;
      if (series_.samples() % 200 == 0) flush();
    }
    log_new_losses(solver);
    const auto now = Clock::now();
    if (std::chrono::duration<double>(now - last_report_).count() > 10.0) {
      last_report_ = now;
      const double elapsed = std::chrono::duration<double>(now - start_).count();
      const double eta = elapsed / std::max(t - first_time_, 1e-30) * (end_time_ - t);
      spdlog::info("t = {:.5f} / {} s, step {}, dt = {:.3e} s, lost {}, elapsed {}, left ~{}", t, end_time_,
                   solver.step_count(), solver.time_step(), solver.lost_count(), hms(elapsed), hms(eta));
    }
  }

  // The next time at which something is due (snapshot or sample), capped at the end time.
  double next_due() const {
    double target = end_time_;
    if (series_interval_ > 0) target = std::min(target, next_sample_);
    if (snapshot_interval_ > 0) target = std::min(target, next_snapshot_);
    return target;
  }

  void flush() {
    if (root_) series_.flush();
  }

  // The state a failed run stopped in (collective when split): a snapshot and a probe row,
  // then the series is written, so the failure can be looked at.
  void write_last_state(const FluidSolver<D>& solver, const Vec<D>& interface_force = {}) {
    snapshots_.write(solver);
    if (solver.time() > last_sample_time_) sample(solver, interface_force);
    flush();
  }

  // A run that stops on an error still leaves its probe series readable.
  ~RunOutput() {
    try {
      flush();
    } catch (const std::exception& e) {
      spdlog::error("fluid_sph: could not write the probe series: {}", e.what());
    }
  }
  RunOutput(const RunOutput&) = delete;
  RunOutput& operator=(const RunOutput&) = delete;
  double elapsed() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

 private:
  void sample(const FluidSolver<D>& solver, const Vec<D>& interface_force) {
    std::vector<double> row;
    for (const auto& q : probes_.pressure_points) row.push_back(pressure_at<D>(solver, q.position));
    for (const auto& q : probes_.flow_planes) row.push_back(flow_rate<D>(solver, q.plane));
    for (const auto& q : probes_.velocity_planes) row.push_back(max_speed_on_plane<D>(solver, q.plane));
    if (probes_.wall_forces || plate_count_ > 0)
      for (int d = 0; d < D; ++d) row.push_back(solver.body_forces()[0][d]);
    for (std::size_t k = 0; k < plate_count_; ++k) {
      for (int d = 0; d < D; ++d) row.push_back(solver.body_forces()[k + 1][d]);
      row.push_back(solver.plates()[k].displacement);
      row.push_back(solver.plates()[k].velocity);
      row.push_back(solver.plates()[k].pressure(solver.time()) + solver.plate_pressure_level());
    }
    row.push_back(static_cast<double>(solver.lost_count()));
    if (interface_) {
      for (int d = 0; d < D; ++d) row.push_back(interface_force[d]);
      const auto* surface = solver.immersed_surface();
      const ImmersedSurfaceCounters counters = surface ? surface->counters() : ImmersedSurfaceCounters{};
      row.push_back(static_cast<double>(counters.corrections));
      row.push_back(static_cast<double>(counters.leaks));
    }
    series_.append(solver.time(), row);
    last_sample_time_ = solver.time();
  }

  // Each particle taken out for its density, once, as a warning (every rank logs its own; a
  // window the coupling repeats takes its losses back and names them again, logged once).
  void log_new_losses(const FluidSolver<D>& solver) {
    const auto& losses = solver.named_losses();
    for (; losses_logged_ < losses.size(); ++losses_logged_) {
      const auto& l = losses[losses_logged_];
      std::string where;
      for (int d = 0; d < D; ++d) where += fmt::format("{}{:.6g}", d ? ", " : "", l.position[d]);
      const double rest = solver.settings().rest_density;
      spdlog::warn("particle {} taken out at t = {:.6g} s (step {}): density {:.5g} kg/m^3 ({:+.1f} % of rest, allowed "
                   "+-{:g} %), at x = ({}) m, speed {:.3g} m/s{}",
                   l.id, l.time, l.step, l.density, 100.0 * (l.density / rest - 1.0),
                   100.0 * solver.settings().max_density_deviation, where, l.speed,
                   l.near_surface ? ", within a support of the leaflets" : "");
      if (losses_logged_ + 1 == FluidSolver<D>::kNamedLosses)
        spdlog::warn("{} particles named as taken out: further ones are only counted", FluidSolver<D>::kNamedLosses);
    }
  }

  ProbeSet<D> probes_;
  std::size_t losses_logged_ = 0;
  std::size_t plate_count_;
  bool interface_;
  bool root_;
  SnapshotWriter<D> snapshots_;
  SeriesWriter series_;
  double end_time_, snapshot_interval_, series_interval_;
  double next_snapshot_ = 0.0, next_sample_ = 0.0;
  double last_sample_time_ = -1.0;
  double first_time_ = std::numeric_limits<double>::quiet_NaN();
  Clock::time_point start_, last_report_;
};

}  // namespace valvefsi::fluid::app
