#pragma once
// The two-sided thin wall inside the SPH fluid (2D; docs/thin-leaflet.md, DESIGN.md section 2):
//   classify          - per particle: closest wall point, side, near-wall flag, candidate
//                       segments; leak check against the side remembered from the last step
//   blocked           - a pair whose connecting segment crosses the wall does not interact
//   update_marker_states - per marker and side: Adami extrapolation of pressure (with the
//                       wall's acceleration) and velocity from that side's fluid only
//   add_wall_rates    - closest-point virtual layers: for fluid particle a, a lattice behind
//                       the closest wall point, counted where the segment from a crosses the
//                       wall, carrying that side's state; adds pressure, viscous, continuity
//                       and kernel-sum terms to a and the opposite force to the markers
//   correct_crossings - after the drift: a particle whose path crossed the moving wall is put
//                       back on its side with its relative normal velocity reflected
//   accept_shift      - particle shifting never crosses or touches the wall
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "valvefsi/fluid/cell_grid.hpp"
#include "valvefsi/fluid/fluid_settings.hpp"
#include "valvefsi/fluid/particles.hpp"
#include "valvefsi/fluid/thin_wall/markers.hpp"
#include "valvefsi/fluid/thin_wall/ordered_node_loads.hpp"
#include "valvefsi/fluid/thin_wall/polyline.hpp"
#include "valvefsi/fluid/thin_wall/restart_arrays.hpp"

namespace valvefsi::fluid::thin_wall {

struct ThinWallSettings {
  // Spacing of the closest-point virtual lattice over dp (the prototype's dp/2).
  double virtual_spacing_ratio = 0.5;
  // Distance from the wall (over dp) at which a put-back particle or a shifted particle must
  // stay at least.
  double clearance_ratio = 0.1;
  // Only virtual points in the wall's true shadow (segment from the particle crosses the
  // wall) count. If false, the whole half-plane lattice behind the closest point counts
  // (a measured alternative; it over-fills the kernel beyond a free edge).
  bool shadow_only = true;
  // Virtual points in the shadow but beyond a free end (their projection on the crossed
  // segment's line lies past the end node) stand where the real fluid is the other side's:
  // give them the other side's state at the end instead of the particle's own side's.
  // (A measured alternative for the free edge; docs/thin-leaflet.md.)
  bool opposite_state_beyond_edge = false;
  // Virtual points beyond a free end move with the extrapolated fluid velocity (in the
  // continuity and viscous terms) instead of the wall's: the fluid there flows round the edge
  // and is not a wall. (A measured alternative; docs/thin-leaflet.md.)
  bool fluid_velocity_beyond_edge = false;
  // A virtual point that the particle could reach round a free end within one kernel support
  // (|x_a - end| + |end - x_v| < R) stands where the real fluid is the other side's: it
  // carries the other side's state (the mirror image of the particle's own side is right
  // only where the wall hides the other side). docs/thin-leaflet.md, "free edge".
  bool other_side_round_edge = false;
  // Such a virtual point moves with that side's extrapolated fluid velocity (continuity and
  // viscous terms), not with the wall.
  bool fluid_velocity_round_edge = false;
  // In the continuity equation a virtual point moves with the fluid particle along the wall
  // and with the wall across it: only the relative normal velocity compresses. (A measured
  // alternative; docs/thin-leaflet.md.)
  bool normal_only_continuity = false;
  // Extrapolate the wall pressure with the wall's acceleration (Adami, Hu & Adams 2012, eq. 27).
  // Right for a prescribed motion; in a coupled run the acceleration comes from the window
  // motion and makes the fluid's added mass act within the window: explicit coupling of a
  // 0.25 mm leaflet then diverges (x40 per window). Off, the oscillating plate's in-phase force
  // changes by 0.4 % (docs/thin-leaflet.md, "Coupled runs").
  bool wall_acceleration_in_pressure = true;
};

// What the model knows of one particle after classify (sorted index).
struct NearWall {
  ClosestPoint closest;
  bool near = false;  // within one kernel support of the wall
};

struct WallCounters {
  std::size_t corrections = 0;  // put-backs after a crossing, since the start
  std::size_t leaks = 0;        // particles found on the other side without a correction
  std::size_t rejected_shifts = 0;
};

class TwoSidedWall {
 public:
  TwoSidedWall(Polyline wall, const FluidSettings<2>& fluid, ThinWallSettings settings = {});

  Polyline& wall() { return wall_; }
  const Polyline& wall() const { return wall_; }
  const MarkerSet& markers() const { return markers_; }
  const ThinWallSettings& settings() const { return settings_; }
  const WallCounters& counters() const { return counters_; }
  const NearWall& near_wall(std::size_t i) const { return near_[i]; }

  // After every sort: closest points, sides and candidate segments of all particles, and the
  // leak check of fluid particles against their remembered side (by particle id).
  void classify(const Particles<2>& particles);
  // True when particles a and b (sorted indices) are on opposite sides of the wall.
  bool blocked(std::uint32_t a, std::uint32_t b, const Particles<2>& particles) const;
  // Per-side wall states of every marker (needs the fluid's pressure).
  void update_marker_states(const Particles<2>& particles, const CellGrid<2>& grid);
  // Adds the virtual layers' terms to the fluid's acceleration, density rate and (if sized)
  // kernel sum and gradient; sets every marker's force to the reaction. Call after the
  // fluid-fluid pass has written the rates.
  void add_wall_rates(Particles<2>& particles);

  // Before the drift: remember the particles' positions (current order) and the wall's nodes.
  void begin_step(const Particles<2>& particles);
  // After the drift and after the wall moved: put back particles whose path crossed it.
  void correct_crossings(Particles<2>& particles);
  // Whether moving fluid particle i (sorted index) from its position by `shift` is allowed.
  bool accept_shift(const Particles<2>& particles, std::size_t i, const Vec2& shift);

  // Restart state (arrays named under `prefix`): the wall's nodes, the markers' states and
  // forces, counters, the last classify's per-particle data in the particle order of the
  // moment, and the side memory by particle id. load_state throws std::runtime_error naming
  // an array that is missing or of the wrong size.
  void save_state(RestartWriter& out, const std::string& prefix) const;
  void load_state(const RestartReader& in, const std::string& prefix);

  // Sum of the virtual-layer kernel weights seen by particle i at the last add_wall_rates
  // (diagnostics of kernel completeness near the edge).
  float virtual_kernel_sum(std::size_t i) const { return i < virtual_kernel_sum_.size() ? virtual_kernel_sum_[i] : 0.0f; }

 private:
  // Logs one leak found by classify (where, across which segment, what the swept test said).
  void log_leak(std::uint32_t id, int remembered, const Vec2& x, const ClosestPoint& c) const;

  Polyline wall_;
  MarkerSet markers_;
  OrderedNodeLoads<2> marker_loads_;  // scratch of add_wall_rates
  std::vector<Vec2> marker_force_;
  FluidSettings<2> fluid_;
  ThinWallSettings settings_;
  WallCounters counters_;
  std::vector<NearWall> near_;
  std::vector<std::vector<std::uint32_t>> candidates_;
  std::vector<std::int8_t> side_by_id_;       // remembered side of each particle id (0: unknown)
  std::vector<std::uint8_t> corrected_by_id_;  // put back during the current step
  std::vector<Vec2> start_position_;
  std::vector<Vec2> previous_by_id_;  // position at the start of the step, by particle id
  std::vector<Vec2> start_nodes_;
  std::vector<float> virtual_kernel_sum_;
  std::array<double, 4> wall_box_{};  // the wall's bounding box: xmin, ymin, xmax, ymax
};

}  // namespace valvefsi::fluid::thin_wall
