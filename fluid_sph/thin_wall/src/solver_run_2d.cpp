#include "valvefsi/fluid/thin_wall/solver_run_2d.hpp"

#include <stdexcept>

#include "valvefsi/fluid/geometry.hpp"

namespace valvefsi::fluid::thin_wall {

ImmersedSurfaceGeometry<2> surface_of(const std::vector<Polyline>& walls) {
  ImmersedSurfaceGeometry<2> g;
  for (const Polyline& w : walls) {
    const auto first = static_cast<std::uint32_t>(g.nodes.size());
    g.nodes.insert(g.nodes.end(), w.position.begin(), w.position.end());
    for (std::uint32_t k = 0; k + 1 < w.node_count(); ++k) {
      g.cells.push_back(first + k);
      g.cells.push_back(first + k + 1);
    }
  }
  g.node_thickness.assign(g.nodes.size(), 0.0);
  return g;
}

ThinWallSolverRun2D::ThinWallSolverRun2D(ThinWallCase2D c, double window)
    : motion_(std::move(c.motion)), scratch_(c.walls), window_(window) {
  if (!(window > 0)) throw std::invalid_argument("ThinWallSolverRun2D: window = " + std::to_string(window) + " s: allowed > 0");
  if (c.walls.empty()) throw std::invalid_argument("ThinWallSolverRun2D: the case has no thin wall");
  if (motion_) motion_(0.0, c.walls);
  const ImmersedSurfaceGeometry<2> g = surface_of(c.walls);
  auto model = std::make_unique<ThinWallModel2D>(g, c.fluid, c.wall_settings, c.coaptation_distance);
  model_ = model.get();
  solver_ = std::make_unique<FluidSolver<2>>(c.fluid, fill_particles<2>(c.scene, c.fluid), std::vector<PressurePlate<2>>{},
                                             std::move(model));
}

void ThinWallSolverRun2D::step() {
  const double t = solver_->time();
  if (motion_ && window_end_ <= t + 1e-12 * window_) {
    window_end_ = t + window_;
    motion_(window_end_, scratch_);
    target_x_.clear();
    target_v_.clear();
    for (const Polyline& w : scratch_) {
      target_x_.insert(target_x_.end(), w.position.begin(), w.position.end());
      target_v_.insert(target_v_.end(), w.velocity.begin(), w.velocity.end());
    }
    model_->set_window_target(window_end_, target_x_, target_v_);
  }
  if (motion_ && t + solver_->time_step() >= window_end_)
    solver_->advance_to(window_end_);
  else
    solver_->step();
}

void ThinWallSolverRun2D::advance_to(double end_time) {
  while (time() < end_time * (1.0 - 1e-12)) step();
}

}  // namespace valvefsi::fluid::thin_wall
