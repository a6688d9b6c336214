#pragma once
// The two-sided thin wall behind FluidSolver's immersed-surface hook (2D): the leaflets the
// coupler sends (unordered segments, possibly several disjoint leaflets) become one
// TwoSidedWall per chain of segments; the model moves them through each coupling window
// (cubic Hermite between the window's start state and the coupler's target), and returns the
// fluid's force on the coupler's nodes (N per metre of depth). docs/thin-leaflet.md.
//
// Coaptation (optional): where two free ends of different leaflets come within the
// coaptation distance, the fluid sees them joined by a bridge, a two-sided wall from one end to
// the other, until they part by more than kCoaptationReleaseFactor times that distance. A 2D
// section cannot close its leaflets onto each other (the shells' contact keeps their
// mid-lines a thickness apart, and the section stands for a 3D line where the leaflets meet
// over millimetres), so without the bridge the closed valve leaks through the tips' gap as
// an orifice (docs/fsi-2d.md, "Session 20"). The bridge's load goes to its two end nodes.
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "thin_wall_case.pb.h"
#include "valvefsi/fluid/fluid_settings.hpp"
#include "valvefsi/fluid/immersed_surface.hpp"
#include "valvefsi/fluid/thin_wall/two_sided_wall.hpp"
#include "valvefsi/fluid/thin_wall/window_motion.hpp"

namespace valvefsi::fluid::thin_wall {

// Orders unordered segments (2 node indices per segment) into chains of node indices, one per
// open polyline. Each chain starts at its lowest-numbered end node (the solid numbers a
// leaflet from its attached end). Throws std::invalid_argument, naming the node or segment,
// for an index out of range, a segment joining a node to itself, a node shared by more than
// two segments (a branch), a repeated segment or a closed loop.
std::vector<std::vector<std::uint32_t>> chains_from_segments(std::size_t node_count, std::span<const std::uint32_t> cells);

using WindowMotion = WindowMotionT<2>;

// A bridge engaged below the coaptation distance is released above this multiple of it, so a
// pair of ends resting near the threshold does not engage and release every step.
inline constexpr double kCoaptationReleaseFactor = 1.25;

// Two free ends that may be bridged, and the bridge while it is engaged.
struct CoaptationBridge {
  std::uint32_t node_a = 0, node_b = 0;  // the coupler's node indices (end of an earlier chain first)
  std::optional<TwoSidedWall> wall;      // engaged: the wall from node_a to node_b
  std::vector<Vec2> reference;           // the two ends when it engaged (its markers' layout)
};

// ImmersedSurfaceModel<2> over one TwoSidedWall per chain. Node indices in the interface are
// those of the coupler's geometry.
class ThinWallModel2D final : public ImmersedSurfaceModel<2> {
 public:
  // coaptation_distance (m): 0 leaves free ends unbridged.
  ThinWallModel2D(const ImmersedSurfaceGeometry<2>& geometry, const FluidSettings<2>& fluid, ThinWallSettings settings,
                  double coaptation_distance = 0.0);

  void set_window_target(double end_time, std::span<const Vec<2>> end_positions,
                         std::span<const Vec<2>> end_velocities) override;
  void move_to(double time) override;
  double max_node_speed() const override;

  void begin_step(const Particles<2>& particles) override;
  void correct_crossings(Particles<2>& particles) override;
  void classify(const Particles<2>& particles) override;
  bool near_surface(std::size_t i) const override;
  bool blocked(std::uint32_t a, std::uint32_t b, const Particles<2>& particles) const override;
  void update_surface_states(const Particles<2>& particles, const CellGrid<2>& grid) override;
  void add_surface_rates(Particles<2>& particles) override;
  bool accept_shift(const Particles<2>& particles, std::size_t i, const Vec<2>& shift) override;

  std::size_t node_count() const override { return node_count_; }
  void node_forces(std::span<Vec<2>> forces) const override;
  ImmersedSurfaceCounters counters() const override;

  void save_checkpoint() override;
  void restore_checkpoint() override;

  // Restart files: the window's motion ("motion.*") and every chain's state ("wall<k>.*":
  // nodes, markers, counters, per-particle data in the particle order of the moment, side
  // memory by particle id); with coaptation, which bridges are engaged ("bridges.engaged"),
  // the released bridges' counters and each engaged bridge ("bridge<k>.*"). A restart written
  // without coaptation loads into a model with it: the bridges start released (logged).
  std::optional<std::vector<NamedArray>> restart_state() const override;
  void load_restart_state(std::span<const NamedArray> arrays) override;

  // Diagnostics and tests.
  const std::vector<std::vector<std::uint32_t>>& chains() const { return chains_; }
  const std::vector<TwoSidedWall>& walls() const { return walls_; }
  const std::vector<double>& node_thickness() const { return thickness_; }
  double time() const { return motion_.current_time(); }
  const std::vector<CoaptationBridge>& bridges() const { return bridges_; }
  double coaptation_distance() const { return coaptation_distance_; }
  std::size_t bridge_engagements() const { return engagements_; }

 private:
  struct Checkpoint {
    WindowMotion motion;
    std::vector<TwoSidedWall> walls;
    std::vector<CoaptationBridge> bridges;
    WallCounters released;
    std::size_t engagements = 0;
  };

  // Engages or releases each bridge from the distance between its ends now.
  void update_bridges();
  // Calls f on every chain's wall and every engaged bridge; stops when f returns false and
  // returns whether all returned true.
  template <class F>
  bool all_walls(F&& f) {
    for (auto& w : walls_)
      if (!f(w)) return false;
    for (auto& b : bridges_)
      if (b.wall && !f(*b.wall)) return false;
    return true;
  }
  template <class F>
  bool all_walls(F&& f) const {
    for (const auto& w : walls_)
      if (!f(w)) return false;
    for (const auto& b : bridges_)
      if (b.wall && !f(*b.wall)) return false;
    return true;
  }
  TwoSidedWall make_bridge_wall(const std::vector<Vec2>& ends, std::uint32_t a, std::uint32_t b) const;

  std::size_t node_count_ = 0;
  std::vector<std::vector<std::uint32_t>> chains_;  // node indices of each wall, in order
  std::vector<double> thickness_;
  std::vector<TwoSidedWall> walls_;
  FluidSettings<2> fluid_;
  ThinWallSettings settings_;
  double coaptation_distance_ = 0.0;
  std::vector<CoaptationBridge> bridges_;
  WallCounters released_;  // counters of bridges since released
  std::size_t engagements_ = 0;
  WindowMotion motion_;
  std::vector<Vec2> x_, v_, a_;  // scratch: all nodes at the last move_to
  std::unique_ptr<Checkpoint> checkpoint_;
};

// The hook's factory for FluidSolver<2>: checks the geometry (segments, thickness per node)
// and the case part (its limits, defaults filled), and builds the model at rest at time 0.
// Throws std::invalid_argument (geometry) or valvefsi::CaseError (case part).
std::unique_ptr<ImmersedSurfaceModel<2>> make_thin_wall_model_2d(const ImmersedSurfaceGeometry<2>& geometry,
                                                                 const FluidSettings<2>& fluid,
                                                                 const valvefsi::cases::FluidThinWalls& walls);

}  // namespace valvefsi::fluid::thin_wall
