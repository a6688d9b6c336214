#include "valvefsi/fluid/thin_wall/thin_wall_model.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

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

ThinWallModel2D::ThinWallModel2D(const ImmersedSurfaceGeometry<2>& g, const FluidSettings<2>& fluid, ThinWallSettings settings,
                                 double coaptation_distance)
    : node_count_(g.nodes.size()),
      chains_((g.nodes_per_cell == 2
                   ? chains_from_segments(g.nodes.size(), g.cells)
                   : throw std::invalid_argument(fmt::format("{}: nodes_per_cell = {}: allowed 2 (segments) in 2D", kSource,
                                                             g.nodes_per_cell)))),
      thickness_(g.node_thickness),
      fluid_(fluid),
      settings_(settings),
      coaptation_distance_(coaptation_distance),
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
  if (!(coaptation_distance >= 0.0) || !std::isfinite(coaptation_distance))
    throw std::invalid_argument(fmt::format("thin wall: coaptation distance {} m: allowed >= 0", coaptation_distance));
  // Every pair of end nodes of different chains may be bridged; each chain's ends come in
  // chain order, so a bridge always runs from an earlier chain's end to a later one's.
  if (coaptation_distance > 0.0)
    for (std::size_t c1 = 0; c1 < chains_.size(); ++c1)
      for (std::size_t c2 = c1 + 1; c2 < chains_.size(); ++c2)
        for (const std::uint32_t a : {chains_[c1].front(), chains_[c1].back()})
          for (const std::uint32_t b : {chains_[c2].front(), chains_[c2].back()}) bridges_.push_back({a, b, std::nullopt, {}});
  move_to(0.0);
}

TwoSidedWall ThinWallModel2D::make_bridge_wall(const std::vector<Vec2>& ends, std::uint32_t a, std::uint32_t b) const {
  // Put-back and shifted particles keep half the thicker end's thickness from the bridge too.
  ThinWallSettings own = settings_;
  own.clearance_ratio = std::max(settings_.clearance_ratio, 0.5 * std::max(thickness_[a], thickness_[b]) / fluid_.particle_spacing);
  return TwoSidedWall(Polyline::at_rest(ends), fluid_, own);
}

void ThinWallModel2D::update_bridges() {
  // Below this length the bridge has no direction (and the ends block pairs by touching).
  const double shortest = 1e-3 * fluid_.particle_spacing;
  for (std::size_t k = 0; k < bridges_.size(); ++k) {
    CoaptationBridge& b = bridges_[k];
    const Vec2 xa = x_[b.node_a], xb = x_[b.node_b];
    const double d = std::hypot(xb[0] - xa[0], xb[1] - xa[1]);
    const bool engage = !b.wall && d < coaptation_distance_ && d > shortest;
    const bool release = b.wall && (d > kCoaptationReleaseFactor * coaptation_distance_ || d <= shortest);
    if (engage) {
      b.reference = {xa, xb};
      b.wall.emplace(make_bridge_wall(b.reference, b.node_a, b.node_b));
      Polyline& w = b.wall->wall();
      w.velocity = {v_[b.node_a], v_[b.node_b]};
      w.acceleration = {a_[b.node_a], a_[b.node_b]};
      ++engagements_;
    } else if (release) {
      const WallCounters& c = b.wall->counters();
      released_.corrections += c.corrections;
      released_.leaks += c.leaks;
      released_.rejected_shifts += c.rejected_shifts;
      b.wall.reset();
    }
    // The first events and then every hundredth: a bridge that chatters says so without
    // flooding the log.
    const std::size_t events = 2 * engagements_ - (b.wall ? 1 : 0);
    if ((engage || release) && (events <= 20 || events % 100 == 0))
      spdlog::info("thin wall: t = {:.5f} s: free ends {} and {} {:.3f} mm apart: coaptation bridge {} (event {})",
                   motion_.current_time(), b.node_a, b.node_b, 1e3 * d, engage ? "engaged" : "released", events);
  }
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
  for (auto& b : bridges_) {
    if (!b.wall) continue;
    Polyline& w = b.wall->wall();
    w.position = {x_[b.node_a], x_[b.node_b]};
    w.velocity = {v_[b.node_a], v_[b.node_b]};
    w.acceleration = {a_[b.node_a], a_[b.node_b]};
  }
}

double ThinWallModel2D::max_node_speed() const {
  double v2 = 0.0;
  for (const auto& v : v_) v2 = std::max(v2, v[0] * v[0] + v[1] * v[1]);
  return std::max(std::sqrt(v2), motion_.max_end_speed());
}

void ThinWallModel2D::begin_step(const Particles<2>& particles) {
  update_bridges();
  all_walls([&](TwoSidedWall& w) { return w.begin_step(particles), true; });
}

void ThinWallModel2D::correct_crossings(Particles<2>& particles) {
  all_walls([&](TwoSidedWall& w) { return w.correct_crossings(particles), true; });
}

void ThinWallModel2D::classify(const Particles<2>& particles) {
  all_walls([&](TwoSidedWall& w) { return w.classify(particles), true; });
}

bool ThinWallModel2D::near_surface(std::size_t i) const {
  return !all_walls([&](const TwoSidedWall& w) { return !w.near_wall(i).near; });
}

bool ThinWallModel2D::blocked(std::uint32_t a, std::uint32_t b, const Particles<2>& particles) const {
  return !all_walls([&](const TwoSidedWall& w) { return !w.blocked(a, b, particles); });
}

void ThinWallModel2D::update_surface_states(const Particles<2>& particles, const CellGrid<2>& grid) {
  all_walls([&](TwoSidedWall& w) { return w.update_marker_states(particles, grid), true; });
}

void ThinWallModel2D::add_surface_rates(Particles<2>& particles) {
  all_walls([&](TwoSidedWall& w) { return w.add_wall_rates(particles), true; });
}

bool ThinWallModel2D::accept_shift(const Particles<2>& particles, std::size_t i, const Vec<2>& shift) {
  // Stops at the first wall that refuses, so a refusal is counted once.
  return all_walls([&](TwoSidedWall& w) { return w.accept_shift(particles, i, shift); });
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
  for (const auto& b : bridges_) {
    if (!b.wall) continue;
    const auto f = b.wall->markers().node_forces(2);
    for (int d = 0; d < 2; ++d) {
      forces[b.node_a][d] += f[0][d];
      forces[b.node_b][d] += f[1][d];
    }
  }
}

ImmersedSurfaceCounters ThinWallModel2D::counters() const {
  ImmersedSurfaceCounters total{released_.corrections, released_.leaks, released_.rejected_shifts};
  all_walls([&](const TwoSidedWall& w) {
    total.corrections += w.counters().corrections;
    total.leaks += w.counters().leaks;
    total.rejected_shifts += w.counters().rejected_shifts;
    return true;
  });
  return total;
}

void ThinWallModel2D::save_checkpoint() {
  checkpoint_ = std::make_unique<Checkpoint>(Checkpoint{motion_, walls_, bridges_, released_, engagements_});
}

void ThinWallModel2D::restore_checkpoint() {
  if (!checkpoint_) throw std::logic_error("thin wall restore_checkpoint: no checkpoint was saved");
  motion_ = checkpoint_->motion;
  walls_ = checkpoint_->walls;
  bridges_ = checkpoint_->bridges;
  released_ = checkpoint_->released;
  engagements_ = checkpoint_->engagements;
  move_to(motion_.current_time());
}

std::optional<std::vector<NamedArray>> ThinWallModel2D::restart_state() const {
  RestartWriter out;
  motion_.save(out, "motion");
  for (std::size_t c = 0; c < walls_.size(); ++c) walls_[c].save_state(out, fmt::format("wall{}", c));
  if (!bridges_.empty()) {
    std::vector<double> engaged;
    for (const auto& b : bridges_) engaged.push_back(b.wall ? 1.0 : 0.0);
    out.scalars("bridges.engaged", engaged);
    out.scalars("bridges.released", std::vector<double>{static_cast<double>(released_.corrections), static_cast<double>(released_.leaks),
                                                        static_cast<double>(released_.rejected_shifts),
                                                        static_cast<double>(engagements_)});
    for (std::size_t k = 0; k < bridges_.size(); ++k) {
      if (!bridges_[k].wall) continue;
      out.vectors(fmt::format("bridge{}.reference", k), bridges_[k].reference);
      bridges_[k].wall->save_state(out, fmt::format("bridge{}", k));
    }
  }
  return out.take();
}

void ThinWallModel2D::load_restart_state(std::span<const NamedArray> arrays) {
  const RestartReader in(arrays, "thin wall 2D restart state");
  // Read into copies first, so that a bad array leaves the model as it was.
  WindowMotion motion = motion_;
  motion.load(in, "motion");
  std::vector<TwoSidedWall> walls = walls_;
  for (std::size_t c = 0; c < walls.size(); ++c) walls[c].load_state(in, fmt::format("wall{}", c));
  std::vector<CoaptationBridge> bridges = bridges_;
  WallCounters released;
  std::size_t engagements = 0;
  if (!bridges.empty() && !in.has("bridges.engaged")) {
    spdlog::warn("thin wall: the restart state has no coaptation bridges (written without them): they start released and "
                 "engage at the first step where two free ends are within {:.3f} mm",
                 1e3 * coaptation_distance_);
    for (auto& b : bridges) b.wall.reset();
  } else if (!bridges.empty()) {
    const auto engaged = in.scalars<double>("bridges.engaged", bridges.size());
    const auto counts = in.scalars<std::size_t>("bridges.released", 4);
    released = {counts[0], counts[1], counts[2]};
    engagements = counts[3];
    for (std::size_t k = 0; k < bridges.size(); ++k) {
      CoaptationBridge& b = bridges[k];
      b.wall.reset();
      if (engaged[k] == 0.0) continue;
      b.reference = in.vectors<2>(fmt::format("bridge{}.reference", k), 2);
      b.wall.emplace(make_bridge_wall(b.reference, b.node_a, b.node_b));
      b.wall->load_state(in, fmt::format("bridge{}", k));
    }
  }
  motion_ = std::move(motion);
  walls_ = std::move(walls);
  bridges_ = std::move(bridges);
  released_ = released;
  engagements_ = engagements;
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
  return std::make_unique<ThinWallModel2D>(geometry, fluid, settings, checked.coaptation_distance());
}

}  // namespace valvefsi::fluid::thin_wall
