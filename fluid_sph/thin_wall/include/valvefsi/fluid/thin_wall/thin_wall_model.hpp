#pragma once
// The two-sided thin wall behind FluidSolver's immersed-surface hook (2D): the leaflets the
// coupler sends (unordered segments, possibly several disjoint leaflets) become one
// TwoSidedWall per chain of segments; the model moves them through each coupling window
// (cubic Hermite between the window's start state and the coupler's target), and returns the
// fluid's force on the coupler's nodes (N per metre of depth). docs/thin-leaflet.md.
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

// ImmersedSurfaceModel<2> over one TwoSidedWall per chain. Node indices in the interface are
// those of the coupler's geometry.
class ThinWallModel2D final : public ImmersedSurfaceModel<2> {
 public:
  ThinWallModel2D(const ImmersedSurfaceGeometry<2>& geometry, const FluidSettings<2>& fluid, ThinWallSettings settings);

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
  // memory by particle id).
  std::optional<std::vector<NamedArray>> restart_state() const override;
  void load_restart_state(std::span<const NamedArray> arrays) override;

  // Diagnostics and tests.
  const std::vector<std::vector<std::uint32_t>>& chains() const { return chains_; }
  const std::vector<TwoSidedWall>& walls() const { return walls_; }
  const std::vector<double>& node_thickness() const { return thickness_; }
  double time() const { return motion_.current_time(); }

 private:
  struct Checkpoint {
    WindowMotion motion;
    std::vector<TwoSidedWall> walls;
  };

  std::size_t node_count_ = 0;
  std::vector<std::vector<std::uint32_t>> chains_;  // node indices of each wall, in order
  std::vector<double> thickness_;
  std::vector<TwoSidedWall> walls_;
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
