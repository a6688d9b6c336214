#pragma once
// Runs a 3D thin-wall scene on FluidSolver<3> with the ThinWallModel3D hook, handing the
// scene's prescribed motion to the model one window at a time, as the coupler hands the
// solid's motion (ThinWallSolverRun2D's 3D counterpart).
#include <memory>

#include "valvefsi/fluid/fluid_solver.hpp"
#include "valvefsi/fluid/thin_wall/scenes_3d.hpp"
#include "valvefsi/fluid/thin_wall/thin_wall_model_3d.hpp"

namespace valvefsi::fluid::thin_wall {

class ThinWallSolverRun3D {
 public:
  explicit ThinWallSolverRun3D(ThinWallCase3D c, double window = 1e-3);

  void step();  // a step never crosses a window's end
  void advance_to(double end_time);

  double time() const { return solver_->time(); }
  long step_count() const { return solver_->step_count(); }
  const FluidSolver<3>& solver() const { return *solver_; }
  FluidSolver<3>& solver() { return *solver_; }
  const Particles<3>& particles() const { return solver_->particles(); }
  const FluidSettings<3>& settings() const { return solver_->settings(); }
  const ThinWallModel3D& model() const { return *model_; }
  // Force of the fluid on the surface at the last step (N).
  Vec3 wall_force() const { return model_->total_force(); }

 private:
  std::unique_ptr<FluidSolver<3>> solver_;
  ThinWallModel3D* model_ = nullptr;  // owned by the solver
  std::function<void(double, std::vector<Vec3>&, std::vector<Vec3>&)> motion_;
  std::vector<Vec3> target_x_, target_v_;
  double window_;
  double window_end_ = 0.0;
};

}  // namespace valvefsi::fluid::thin_wall
