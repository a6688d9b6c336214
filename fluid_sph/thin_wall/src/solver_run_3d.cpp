#include "valvefsi/fluid/thin_wall/solver_run_3d.hpp"

#include <stdexcept>
#include <string>

#include "valvefsi/fluid/geometry.hpp"

namespace valvefsi::fluid::thin_wall {

ThinWallSolverRun3D::ThinWallSolverRun3D(ThinWallCase3D c, double window) : motion_(std::move(c.motion)), window_(window) {
  if (!(window > 0)) throw std::invalid_argument("ThinWallSolverRun3D: window = " + std::to_string(window) + " s: allowed > 0");
  if (motion_) {
    std::vector<Vec3> v;
    motion_(0.0, c.surface.nodes, v);
  }
  auto model = std::make_unique<ThinWallModel3D>(c.surface, c.fluid, c.wall_settings);
  model_ = model.get();
  solver_ = std::make_unique<FluidSolver<3>>(c.fluid, fill_particles<3>(c.scene, c.fluid), std::vector<PressurePlate<3>>{},
                                             std::move(model));
}

void ThinWallSolverRun3D::step() {
  const double t = solver_->time();
  if (motion_ && window_end_ <= t + 1e-12 * window_) {
    window_end_ = t + window_;
    motion_(window_end_, target_x_, target_v_);
    model_->set_window_target(window_end_, target_x_, target_v_);
  }
  if (motion_ && t + solver_->time_step() >= window_end_)
    solver_->advance_to(window_end_);
  else
    solver_->step();
}

void ThinWallSolverRun3D::advance_to(double end_time) {
  while (time() < end_time * (1.0 - 1e-12)) step();
}

}  // namespace valvefsi::fluid::thin_wall
