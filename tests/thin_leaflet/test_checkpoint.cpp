// In-memory checkpoint of the fluid with a thin wall (implicit coupling, docs/coupling.md): a
// window run again after restore_checkpoint() must give the node loads of its first run bit
// for bit, whether the window before it ran once or was itself repeated. Otherwise the
// coupler's fixed-point iterations see a fluid whose answer to the same motion changes
// between passes, and no acceleration converges (issue 8, docs/thin-leaflet.md "Coupled runs").
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <memory>
#include <vector>

#include "valvefsi/fluid/fluid_solver.hpp"
#include "valvefsi/fluid/geometry.hpp"
#include "valvefsi/fluid/thin_wall/scenes_2d.hpp"
#include "valvefsi/fluid/thin_wall/scenes_3d.hpp"
#include "valvefsi/fluid/thin_wall/thin_wall_model.hpp"
#include "valvefsi/fluid/thin_wall/thin_wall_model_3d.hpp"

namespace valvefsi::fluid::thin_wall {
namespace {

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// A solver fed windows of prescribed motion the way fluid_sph's participant loop feeds it:
// restore and/or save first, then the window's end state, then the steps.
template <int D>
struct CoupledFluid {
  double window_size = 0.0;
  std::unique_ptr<FluidSolver<D>> solver;
  std::function<void(double, std::vector<Vec<D>>&, std::vector<Vec<D>>&)> targets;

  // nudge: every end position moved by that many units in the last place (continuity check).
  std::vector<Vec<D>> pass(int k, bool restore, bool save, int nudge = 0) {
    if (restore) solver->restore_checkpoint();
    if (save) solver->save_checkpoint();
    const double end = (k + 1) * window_size;
    std::vector<Vec<D>> x, v;
    targets(end, x, v);
    for (auto& xj : x)
      for (int d = 0; d < D; ++d)
        for (int u = 0; u < nudge; ++u) xj[d] = std::nextafter(xj[d], 1.0);
    solver->immersed_surface()->set_window_target(end, x, v);
    solver->reset_surface_force_average();
    solver->advance_to(end);
    return solver->surface_force_average();
  }
  // Window k run `passes` times from the same checkpoint; the node loads of each pass.
  std::vector<std::vector<Vec<D>>> window(int k, int passes) {
    std::vector<std::vector<Vec<D>>> loads;
    for (int p = 0; p < passes; ++p) loads.push_back(pass(k, p > 0, p == 0));
    return loads;
  }
};

// Windows 0..n-1 run twice each (as implicit windows that converge on the second pass), then
// window n: its repeated passes must give the loads of its first.
template <int D>
void check_repeated_windows(CoupledFluid<D> run, int n) {
  for (int k = 0; k < n; ++k) {
    const auto loads = run.window(k, 2);
    EXPECT_TRUE(same_bits(loads[0], loads[1])) << "window " << k << ": the pass after restore differs from the first";
  }
  const auto loads = run.window(n, 3);
  EXPECT_TRUE(same_bits(loads[0], loads[1])) << "window " << n << ": the pass after restore differs from the first";
  EXPECT_TRUE(same_bits(loads[1], loads[2])) << "window " << n << ": two passes after restore differ";
  double sum = 0.0;
  for (const auto& f : loads[0])
    for (int d = 0; d < D; ++d) sum += std::abs(f[d]);
  EXPECT_GT(sum, 0.0) << "the wall feels no load: the check would be empty";
}

CoupledFluid<2> plate_run() {
  OscillatingPlate plate;
  plate.amplitude = 0.01;
  plate.period = 0.05;  // up to 1.3 m/s: put-backs and shifting happen
  auto c = std::make_shared<ThinWallCase2D>(oscillating_plate_box(0.02, plate));
  c->fluid.shifting = 1.0;
  c->motion(0.0, c->walls);
  ImmersedSurfaceGeometry<2> g;
  for (const Polyline& w : c->walls) {
    const auto first = static_cast<std::uint32_t>(g.nodes.size());
    g.nodes.insert(g.nodes.end(), w.position.begin(), w.position.end());
    for (std::uint32_t k = 0; k + 1 < w.node_count(); ++k) {
      g.cells.push_back(first + k);
      g.cells.push_back(first + k + 1);
    }
  }
  g.node_thickness.assign(g.nodes.size(), 0.0);
  CoupledFluid<2> r;
  r.window_size = 2e-3;
  r.solver = std::make_unique<FluidSolver<2>>(c->fluid, fill_particles<2>(c->scene, c->fluid), std::vector<PressurePlate<2>>{},
                                              std::make_unique<ThinWallModel2D>(g, c->fluid, c->wall_settings));
  r.targets = [c](double t, std::vector<Vec2>& x, std::vector<Vec2>& v) {
    std::vector<Polyline> walls = c->walls;
    c->motion(t, walls);
    x.clear();
    v.clear();
    for (const Polyline& w : walls) {
      x.insert(x.end(), w.position.begin(), w.position.end());
      v.insert(v.end(), w.velocity.begin(), w.velocity.end());
    }
  };
  return r;
}

TEST(ThinWallCheckpoint, TwoDimensionalPassAfterRestoreRepeatsTheFirst) { check_repeated_windows<2>(plate_run(), 3); }

// The loads of one step depend continuously on the motion: end positions moved by 64 units in
// the last place (~1e-16 m) change the node loads of each of three steps by round-off only.
// (Over a whole window of ~120 steps the same nudge changes the window-averaged loads by ~1 %:
// the particles' float state amplifies it, docs/thin-leaflet.md "Coupled runs".)
TEST(ThinWallCheckpoint, TwoDimensionalStepLoadsAreContinuousInTheMotion) {
  CoupledFluid<2> run = plate_run();
  for (int k = 0; k < 3; ++k) run.pass(k, false, false);
  const double end = 4 * run.window_size;
  std::vector<std::vector<Vec2>> loads[2];
  for (int nudge : {0, 64}) {
    if (nudge == 0) run.solver->save_checkpoint();
    else run.solver->restore_checkpoint();
    std::vector<Vec2> x, v;
    run.targets(end, x, v);
    for (auto& xj : x)
      for (int d = 0; d < 2; ++d)
        for (int u = 0; u < nudge; ++u) xj[d] = std::nextafter(xj[d], 1.0);
    run.solver->immersed_surface()->set_window_target(end, x, v);
    for (int step = 0; step < 3; ++step) {
      run.solver->step();
      std::vector<Vec2> f(run.solver->immersed_surface()->node_count());
      run.solver->immersed_surface()->node_forces(f);
      loads[nudge == 0 ? 0 : 1].push_back(f);
    }
  }
  for (int step = 0; step < 3; ++step) {
    double diff = 0.0, norm = 0.0;
    for (std::size_t j = 0; j < loads[0][step].size(); ++j)
      for (int d = 0; d < 2; ++d) {
        diff += std::pow(loads[1][step][j][d] - loads[0][step][j][d], 2);
        norm += std::pow(loads[0][step][j][d], 2);
      }
    ASSERT_GT(norm, 0.0);
    EXPECT_LT(std::sqrt(diff / norm), 1e-10) << "step " << step;
  }
}

TEST(ThinWallCheckpoint, TwoDimensionalFirstWindowRepeats) { check_repeated_windows<2>(plate_run(), 0); }

TEST(ThinWallCheckpoint, ThreeDimensionalPassAfterRestoreRepeatsTheFirst) {
  RockingFlap flap;
  flap.period = 0.04;
  auto c = std::make_shared<ThinWallCase3D>(rocking_flap_box(0.02, flap));
  c->fluid.sound_speed = 30.0;  // the scene's 40 L / T would be 300 m/s: 10x the steps
  c->fluid.shifting = 1.0;
  {
    std::vector<Vec3> v;
    c->motion(0.0, c->surface.nodes, v);
  }
  CoupledFluid<3> r;
  r.window_size = 2e-3;
  r.solver = std::make_unique<FluidSolver<3>>(c->fluid, fill_particles<3>(c->scene, c->fluid), std::vector<PressurePlate<3>>{},
                                              std::make_unique<ThinWallModel3D>(c->surface, c->fluid, c->wall_settings));
  r.targets = [c](double t, std::vector<Vec3>& x, std::vector<Vec3>& v) { c->motion(t, x, v); };
  check_repeated_windows<3>(std::move(r), 2);
}

}  // namespace
}  // namespace valvefsi::fluid::thin_wall
