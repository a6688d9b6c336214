#pragma once
// Runs a 2D thin-wall scene on the project's FluidSolver<2> with the ThinWallModel2D hook,
// handing the scene's prescribed wall motion to the model one window at a time, as the
// coupler hands the solid's motion (target positions and velocities at the window's end).
// The proofs in tests/thin_leaflet and the experiment program use it.
#include <memory>

#include "valvefsi/fluid/fluid_solver.hpp"
#include "valvefsi/fluid/thin_wall/thin_wall_model.hpp"
#include "valvefsi/fluid/thin_wall/scenes_2d.hpp"

namespace valvefsi::fluid::thin_wall {

// The walls as the coupler would send them: one node list, segments along each wall, no
// thickness.
ImmersedSurfaceGeometry<2> surface_of(const std::vector<Polyline>& walls);

class ThinWallSolverRun2D {
 public:
  // `window`: length of the motion windows (s); the motion between window ends is the
  // model's cubic Hermite interpolation.
  explicit ThinWallSolverRun2D(ThinWallCase2D c, double window = 1e-3);

  // One solver step; a step never crosses a window's end (the last one is shortened).
  void step();
  void advance_to(double end_time);

  double time() const { return solver_->time(); }
  long step_count() const { return solver_->step_count(); }
  std::size_t lost_count() const { return solver_->lost_count(); }
  const FluidSolver<2>& solver() const { return *solver_; }
  FluidSolver<2>& solver() { return *solver_; }
  const Particles<2>& particles() const { return solver_->particles(); }
  const FluidSettings<2>& settings() const { return solver_->settings(); }
  const ThinWallModel2D& model() const { return *model_; }
  // The scene's first wall (its nodes at the current time).
  const TwoSidedWall& wall_model() const { return model_->walls().front(); }
  // Force of the fluid on the first wall at the last step (N per unit depth).
  Vec2 wall_force() const { return wall_model().markers().total_force(); }

 private:
  std::unique_ptr<FluidSolver<2>> solver_;
  ThinWallModel2D* model_ = nullptr;  // owned by the solver
  std::function<void(double, std::vector<Polyline>&)> motion_;
  std::vector<Polyline> scratch_;
  std::vector<Vec2> target_x_, target_v_;
  double window_;
  double window_end_ = 0.0;
};

}  // namespace valvefsi::fluid::thin_wall
