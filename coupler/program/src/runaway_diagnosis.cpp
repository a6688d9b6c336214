#include "valvefsi/coupler/runaway_diagnosis.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <tuple>
#include <utility>

namespace valvefsi::coupler {

void InterfaceHistory::update(const Eigen::Matrix3Xd& velocities, double load_work, double fluid_work) {
  velocities_.push_back(velocities);
  if (static_cast<int>(velocities_.size()) > kWindows + 4) velocities_.pop_front();
  work_.push_back(load_work);
  fluid_work_.push_back(fluid_work);
  if (static_cast<int>(work_.size()) > kWorkBlocks * kWindows) {
    work_.pop_front();
    fluid_work_.pop_front();
  }
}

double InterfaceHistory::created_work() const {
  double sum = 0.0;
  for (std::size_t k = 0; k < work_.size(); ++k) sum += work_[k] - fluid_work_[k];
  return sum;
}

std::vector<Eigen::Vector3d> InterfaceHistory::node_velocities(Eigen::Index node) const {
  std::vector<Eigen::Vector3d> v;
  for (const auto& window : velocities_) v.emplace_back(window.col(node));
  return v;
}

std::deque<double> InterfaceHistory::block_work() const {
  std::deque<double> blocks;
  for (auto end = work_.size(); end > 0;) {
    const auto begin = end >= static_cast<std::size_t>(kWindows) ? end - kWindows : 0;
    double sum = 0.0;
    for (auto k = begin; k < end; ++k) sum += work_[k];
    blocks.push_front(sum);
    end = begin;
  }
  return blocks;
}

double equivalent_period(double jump_rms, double speed_rms) {
  // A speed of exactly 0 with jumps (a node set moving within one window) is as short as it gets.
  const double ratio = speed_rms > 0.0 ? jump_rms / speed_rms : (jump_rms > 0.0 ? 4.0 : 0.0);
  if (ratio >= 4.0) return 2.0;
  if (ratio <= 0.0) return std::numeric_limits<double>::infinity();
  return std::numbers::pi / std::asin(std::sqrt(ratio) / 2.0);
}

namespace {

std::vector<Eigen::Vector3d> jumps_of(const std::vector<Eigen::Vector3d>& x) {
  std::vector<Eigen::Vector3d> d;
  for (std::size_t n = 2; n < x.size(); ++n) d.emplace_back(x[n] - 2.0 * x[n - 1] + x[n - 2]);
  return d;
}

// RMS over the last `count` jumps of x and over x centred on them (x[n - 1] for d[n - 2]).
std::pair<double, double> jump_and_centred_rms(const std::vector<Eigen::Vector3d>& x, std::size_t count) {
  const auto d = jumps_of(x);
  double jump = 0.0, centred = 0.0;
  for (std::size_t k = d.size() - count; k < d.size(); ++k) {
    jump += d[k].squaredNorm();
    centred += x[k + 1].squaredNorm();
  }
  return {std::sqrt(jump / count), std::sqrt(centred / count)};
}

}  // namespace

RunawayDiagnosis diagnose_runaway(const InterfaceHistory& history, Eigen::Index node) {
  RunawayDiagnosis d;
  d.node = node;
  d.block_work = history.block_work();
  for (double w : d.block_work) {
    d.net_work += w;
    if (w > 0.0) ++d.positive_blocks;
  }
  d.created_work = history.created_work();
  const auto v = history.node_velocities(node);
  // The jumps' own period needs two jumps of jumps: five windows.
  if (v.size() < 5) return d;
  const auto count = std::min<std::size_t>(InterfaceHistory::kWindows, v.size() - 4);
  d.jumps = static_cast<int>(count);
  std::tie(d.jump_rms, d.speed_rms) = jump_and_centred_rms(v, count);
  d.velocity_period = equivalent_period(d.jump_rms, d.speed_rms);
  const auto [jump_of_jump_rms, centred_jump_rms] = jump_and_centred_rms(jumps_of(v), count);
  d.period_windows = equivalent_period(jump_of_jump_rms, centred_jump_rms);
  if (d.period_windows <= kWindowScalePeriod) {
    d.kind = RunawayDiagnosis::Kind::window_scale;
  } else {
    const double fluid_work = d.net_work - d.created_work;
    d.kind = fluid_work > 0.0            ? RunawayDiagnosis::Kind::smooth_fluid_work
             : d.created_work > 0.0      ? RunawayDiagnosis::Kind::smooth_coupling_lag
                                         : RunawayDiagnosis::Kind::smooth_no_fluid_work;
  }
  return d;
}

namespace {

const char* kAddedMassRemedy =
    "Under explicit coupling this is the added-mass instability (the leaflet is too light for the window, "
    "docs/coupling-numerics.md): use a smaller coupling.window_size, scheme SERIAL_IMPLICIT, or a heavier or "
    "thicker leaflet";
const char* kImplicitRemedy =
    "The implicit iterations did not hold it: try a smaller coupling.window_size or relative_tolerance";

std::string time_scale(const RunawayDiagnosis& d) {
  return fmt::format(
      "node {}'s velocity jumps from window to window by {:.3g} m/s RMS against a speed of {:.3g} m/s RMS over the "
      "last {} windows, the jumps with an equivalent period of {:.3g} windows (the velocity's {:.3g}; up to {:g} is "
      "the window's scale: the added-mass mode's is 2-4 on the 1D piston, ~9 on the 2D valve)",
      d.node, d.jump_rms, d.speed_rms, d.jumps, d.period_windows, d.velocity_period, kWindowScalePeriod);
}

std::string work(const RunawayDiagnosis& d) {
  const auto blocks = d.block_work.size();
  return fmt::format(
      "{:.3g} J on the solid over its last {} block{} of up to {} windows (positive in {} of them): {:.3g} J the "
      "fluid gave (F . v dt) and {:.3g} J the coupling's lag created (F . (dx - v dt))",
      d.net_work, blocks, blocks == 1 ? "" : "s", InterfaceHistory::kWindows, d.positive_blocks,
      d.net_work - d.created_work, d.created_work);
}

}  // namespace

std::string explain_runaway(const RunawayDiagnosis& d, SchemeKind scheme) {
  const char* remedy = scheme == SchemeKind::serial_implicit ? kImplicitRemedy : kAddedMassRemedy;
  if (d.kind == RunawayDiagnosis::Kind::too_early) return fmt::format("Too early in the run to measure its time scale. {}", remedy);
  if (d.kind == RunawayDiagnosis::Kind::window_scale) {
    return fmt::format("It grows at the window's scale: {}; the fluid's loads did net work {}. {}", time_scale(d), work(d), remedy);
  }
  // Smooth growth: where the energy comes from decides what to change.
  const char* not_the_window = "not the coupling's added-mass instability, and a smaller window or implicit coupling will "
                               "not stop it";
  const char* source = "";
  if (d.kind == RunawayDiagnosis::Kind::smooth_fluid_work) {
    source = "the energy comes in from the fluid's side. Look there: blood in tension next to the leaflet (a background "
             "pressure or a plate pressure floor), the fluid's time step (fluid.cfl), its resolution at the leaflet "
             "(particle spacing against the leaflet), its sound speed c0 (docs/fsi-3d.md, \"The closed valve under "
             "diastolic load\")";
  } else if (d.kind == RunawayDiagnosis::Kind::smooth_coupling_lag) {
    not_the_window = "not the coupling's added-mass mode";
    source = "the energy is created at the interface by the explicit coupling's lag, not given by the fluid. Try a "
             "smaller coupling.window_size or scheme SERIAL_IMPLICIT (which remove that energy), and the fluid's time "
             "step against the window (fluid.cfl; docs/stability-map.md, \"Window against fluid step\")";
  } else {
    source = "the energy does not come in through the interface. Look at the solid (its time step and energy balance, "
             "solid.max_energy_balance_error)";
  }
  return fmt::format("It grows smoothly over many windows: {}. So it is {}. The fluid's loads did net work {}: {}",
                     time_scale(d), not_the_window, work(d), source);
}

}  // namespace valvefsi::coupler
