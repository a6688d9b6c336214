#include "valvefsi/fluid/thin_wall/thin_wall_model.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "valvefsi/case/case_loader.hpp"

namespace valvefsi::fluid::thin_wall {
namespace {

constexpr const char* kSource = "interface surface from the coupler";

}  // namespace

std::vector<std::vector<std::uint32_t>> chains_from_segments(std::size_t node_count, std::span<const std::uint32_t> cells) {
  if (cells.size() % 2 != 0)
    throw std::invalid_argument(fmt::format("{}: cells has {} entries: allowed 2 per segment", kSource, cells.size()));
  const std::size_t segments = cells.size() / 2;
  // Up to two segments per node.
  std::vector<std::array<std::int64_t, 2>> at(node_count, {-1, -1});
  for (std::size_t k = 0; k < segments; ++k) {
    const std::uint32_t a = cells[2 * k], b = cells[2 * k + 1];
    for (const std::uint32_t n : {a, b})
      if (n >= node_count)
        throw std::invalid_argument(
            fmt::format("{}: segment {} names node {}: allowed 0 to {}", kSource, k, n, node_count == 0 ? 0 : node_count - 1));
    if (a == b) throw std::invalid_argument(fmt::format("{}: segment {} joins node {} to itself", kSource, k, a));
    for (const std::uint32_t n : {a, b}) {
      auto& slot = at[n];
      if (slot[0] >= 0 && slot[1] >= 0)
        throw std::invalid_argument(
            fmt::format("{}: node {} is shared by more than two segments ({}, {}, {}): a leaflet is an unbranched polyline",
                        kSource, n, slot[0], slot[1], k));
      const std::uint32_t other = n == a ? b : a;
      if (slot[0] >= 0 && (cells[2 * slot[0]] == other || cells[2 * slot[0] + 1] == other))
        throw std::invalid_argument(fmt::format("{}: segments {} and {} both join nodes {} and {}", kSource, slot[0], k, a, b));
      slot[slot[0] < 0 ? 0 : 1] = static_cast<std::int64_t>(k);
    }
  }
  std::vector<std::uint8_t> used(segments, 0);
  std::vector<std::vector<std::uint32_t>> chains;
  // Walk from every end node (one segment), lowest index first.
  for (std::uint32_t start = 0; start < node_count; ++start) {
    if (at[start][0] < 0 || at[start][1] >= 0 || used[static_cast<std::size_t>(at[start][0])]) continue;
    std::vector<std::uint32_t> chain{start};
    std::uint32_t node = start;
    std::int64_t seg = at[start][0];
    while (seg >= 0 && !used[static_cast<std::size_t>(seg)]) {
      used[static_cast<std::size_t>(seg)] = 1;
      const auto s = static_cast<std::size_t>(seg);
      node = cells[2 * s] == node ? cells[2 * s + 1] : cells[2 * s];
      chain.push_back(node);
      seg = at[node][0] == seg ? at[node][1] : at[node][0];
    }
    chains.push_back(std::move(chain));
  }
  for (std::size_t k = 0; k < segments; ++k)
    if (!used[k])
      throw std::invalid_argument(
          fmt::format("{}: segment {} (nodes {}, {}) is part of a closed loop: a leaflet is an open polyline", kSource, k,
                      cells[2 * k], cells[2 * k + 1]));
  return chains;
}

ThinWallModel2D::ThinWallModel2D(const ImmersedSurfaceGeometry<2>& g, const FluidSettings<2>& fluid, ThinWallSettings settings)
    : node_count_(g.nodes.size()),
      chains_((g.nodes_per_cell == 2
                   ? chains_from_segments(g.nodes.size(), g.cells)
                   : throw std::invalid_argument(fmt::format("{}: nodes_per_cell = {}: allowed 2 (segments) in 2D", kSource,
                                                             g.nodes_per_cell)))),
      thickness_(g.node_thickness),
      motion_(std::vector<Vec2>(g.nodes.begin(), g.nodes.end()), 0.0) {
  if (thickness_.size() != node_count_)
    throw std::invalid_argument(
        fmt::format("{}: node_thickness has {} entries: allowed one per node ({})", kSource, thickness_.size(), node_count_));
  for (std::size_t k = 0; k < node_count_; ++k)
    if (!(thickness_[k] >= 0.0) || !(thickness_[k] < fluid.particle_spacing))
      throw std::invalid_argument(fmt::format("{}: node_thickness[{}] = {} m: allowed 0 <= t < the particle spacing {} m",
                                              kSource, k, thickness_[k], fluid.particle_spacing));
  if (chains_.empty()) throw std::invalid_argument(fmt::format("{}: no segments: a thin wall needs at least one", kSource));
  for (const auto& chain : chains_) {
    std::vector<Vec2> nodes;
    double thickest = 0.0;
    for (std::size_t k = 0; k < chain.size(); ++k) {
      nodes.push_back(g.nodes[chain[k]]);
      thickest = std::max(thickest, thickness_[chain[k]]);
      if (k > 0 && nodes[k] == nodes[k - 1])
        throw std::invalid_argument(fmt::format("{}: nodes {} and {} of a segment coincide at ({}, {}) m", kSource,
                                                chain[k - 1], chain[k], nodes[k][0], nodes[k][1]));
    }
    // The mid-line model keeps put-back and shifted particles at least half the leaflet's
    // thickness from its mid-line.
    ThinWallSettings own = settings;
    own.clearance_ratio = std::max(settings.clearance_ratio, 0.5 * thickest / fluid.particle_spacing);
    walls_.emplace_back(Polyline::at_rest(std::move(nodes)), fluid, own);
  }
  move_to(0.0);
}

void ThinWallModel2D::set_window_target(double end_time, std::span<const Vec<2>> end_positions,
                                        std::span<const Vec<2>> end_velocities) {
  motion_.set_target(end_time, end_positions, end_velocities);
}

void ThinWallModel2D::move_to(double time) {
  motion_.evaluate(time, x_, v_, a_);
  for (std::size_t c = 0; c < chains_.size(); ++c) {
    Polyline& w = walls_[c].wall();
    const auto& chain = chains_[c];
    for (std::size_t k = 0; k < chain.size(); ++k) {
      w.position[k] = x_[chain[k]];
      w.velocity[k] = v_[chain[k]];
      w.acceleration[k] = a_[chain[k]];
    }
  }
}

double ThinWallModel2D::max_node_speed() const {
  double v2 = 0.0;
  for (const auto& v : v_) v2 = std::max(v2, v[0] * v[0] + v[1] * v[1]);
  return std::max(std::sqrt(v2), motion_.max_end_speed());
}

void ThinWallModel2D::begin_step(const Particles<2>& particles) {
  for (auto& w : walls_) w.begin_step(particles);
}

void ThinWallModel2D::correct_crossings(Particles<2>& particles) {
  for (auto& w : walls_) w.correct_crossings(particles);
}

void ThinWallModel2D::classify(const Particles<2>& particles) {
  for (auto& w : walls_) w.classify(particles);
}

bool ThinWallModel2D::near_surface(std::size_t i) const {
  for (const auto& w : walls_)
    if (w.near_wall(i).near) return true;
  return false;
}

bool ThinWallModel2D::blocked(std::uint32_t a, std::uint32_t b, const Particles<2>& particles) const {
  for (const auto& w : walls_)
    if (w.blocked(a, b, particles)) return true;
  return false;
}

void ThinWallModel2D::update_surface_states(const Particles<2>& particles, const CellGrid<2>& grid) {
  for (auto& w : walls_) w.update_marker_states(particles, grid);
}

void ThinWallModel2D::add_surface_rates(Particles<2>& particles) {
  for (auto& w : walls_) w.add_wall_rates(particles);
}

bool ThinWallModel2D::accept_shift(const Particles<2>& particles, std::size_t i, const Vec<2>& shift) {
  // Stops at the first wall that refuses, so a refusal is counted once.
  for (auto& w : walls_)
    if (!w.accept_shift(particles, i, shift)) return false;
  return true;
}

void ThinWallModel2D::node_forces(std::span<Vec<2>> forces) const {
  if (forces.size() != node_count_)
    throw std::invalid_argument(fmt::format("thin wall node_forces: {} entries given: needs one per node ({})", forces.size(), node_count_));
  std::fill(forces.begin(), forces.end(), Vec<2>{0.0, 0.0});
  for (std::size_t c = 0; c < chains_.size(); ++c) {
    const auto& chain = chains_[c];
    const auto f = walls_[c].markers().node_forces(chain.size());
    for (std::size_t k = 0; k < chain.size(); ++k)
      for (int d = 0; d < 2; ++d) forces[chain[k]][d] += f[k][d];
  }
}

ImmersedSurfaceCounters ThinWallModel2D::counters() const {
  ImmersedSurfaceCounters total;
  for (const auto& w : walls_) {
    total.corrections += w.counters().corrections;
    total.leaks += w.counters().leaks;
    total.rejected_shifts += w.counters().rejected_shifts;
  }
  return total;
}

void ThinWallModel2D::save_checkpoint() { checkpoint_ = std::make_unique<Checkpoint>(Checkpoint{motion_, walls_}); }

void ThinWallModel2D::restore_checkpoint() {
  if (!checkpoint_) throw std::logic_error("thin wall restore_checkpoint: no checkpoint was saved");
  motion_ = checkpoint_->motion;
  walls_ = checkpoint_->walls;
  move_to(motion_.current_time());
}

std::optional<std::vector<NamedArray>> ThinWallModel2D::restart_state() const {
  RestartWriter out;
  motion_.save(out, "motion");
  for (std::size_t c = 0; c < walls_.size(); ++c) walls_[c].save_state(out, fmt::format("wall{}", c));
  return out.take();
}

void ThinWallModel2D::load_restart_state(std::span<const NamedArray> arrays) {
  const RestartReader in(arrays, "thin wall 2D restart state");
  // Read into copies first, so that a bad array leaves the model as it was.
  WindowMotion motion = motion_;
  motion.load(in, "motion");
  std::vector<TwoSidedWall> walls = walls_;
  for (std::size_t c = 0; c < walls.size(); ++c) walls[c].load_state(in, fmt::format("wall{}", c));
  motion_ = std::move(motion);
  walls_ = std::move(walls);
  motion_.evaluate(motion_.current_time(), x_, v_, a_);
}

std::unique_ptr<ImmersedSurfaceModel<2>> make_thin_wall_model_2d(const ImmersedSurfaceGeometry<2>& geometry,
                                                                 const FluidSettings<2>& fluid,
                                                                 const valvefsi::cases::FluidThinWalls& walls) {
  valvefsi::cases::FluidThinWalls checked = walls;
  apply_field_limits(checked, "fluid case", "fluid.thin_walls");
  ThinWallSettings settings;
  settings.virtual_spacing_ratio = checked.virtual_spacing_ratio();
  settings.clearance_ratio = checked.clearance_ratio();
  settings.wall_acceleration_in_pressure = checked.wall_acceleration_in_pressure();
  return std::make_unique<ThinWallModel2D>(geometry, fluid, settings);
}

}  // namespace valvefsi::fluid::thin_wall
