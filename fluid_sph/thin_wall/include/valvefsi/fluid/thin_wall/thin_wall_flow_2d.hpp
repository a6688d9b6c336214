#pragma once
// A compact 2D SPH driver with one two-sided thin wall, for the wall model's proofs until
// FluidSolver calls the model itself (docs/thin-leaflet.md, "Integration"). It reuses the
// library's particles, lattice fill, cell grid, kernels, equation of state and pressure pass,
// and repeats FluidSolver's kick-drift-kick step with the wall model's calls in place. Its own
// pair passes differ from the library's only by pair blocking (the library's SIMD cell-block
// loop has no per-pair predicate yet).
#include <cstddef>
#include <functional>

#include "valvefsi/fluid/cell_grid.hpp"
#include "valvefsi/fluid/fluid_settings.hpp"
#include "valvefsi/fluid/geometry.hpp"
#include "valvefsi/fluid/particles.hpp"
#include "valvefsi/fluid/thin_wall/two_sided_wall.hpp"

namespace valvefsi::fluid::thin_wall {

struct ThinWallCase2D {
  FluidSettings<2> fluid;
  ThinWallSettings wall_settings;
  SceneGeometry<2> scene;  // rigid tank walls and fluid blocks (fill_particles)
  Polyline wall;           // the thin wall at t = 0
  // Prescribed motion: sets the wall's node positions, velocities and accelerations at a
  // time. Empty: the wall stays fixed.
  std::function<void(double time, Polyline& wall)> motion;
};

class ThinWallFlow2D {
 public:
  explicit ThinWallFlow2D(ThinWallCase2D c);

  void step();
  void advance_to(double end_time);

  double time() const { return time_; }
  double time_step() const { return dt_; }
  long step_count() const { return steps_; }
  std::size_t lost_count() const { return lost_; }
  const FluidSettings<2>& settings() const { return settings_; }
  const Particles<2>& particles() const { return particles_; }
  const TwoSidedWall& wall_model() const { return wall_; }
  // Force of the fluid on the thin wall at the last evaluation (N per unit depth).
  Vec2 wall_force() const { return wall_.markers().total_force(); }
  // Force of the fluid on the rigid tank (its dummy particles).
  Vec2 tank_force() const { return tank_force_; }

 private:
  void evaluate_rates();
  void update_tank_state();
  void compute_fluid_rates();
  void shift_particles(double dt);
  void choose_time_step();

  FluidSettings<2> settings_;
  Particles<2> particles_;
  CellGrid<2> grid_;
  TwoSidedWall wall_;
  std::function<void(double, Polyline&)> motion_;
  Vec2 tank_force_{};
  double time_ = 0.0;
  double dt_ = 0.0;
  long steps_ = 0;
  std::size_t lost_ = 0;
  double max_speed_ = 0.0;
  double max_acceleration_ = 0.0;
};

}  // namespace valvefsi::fluid::thin_wall
