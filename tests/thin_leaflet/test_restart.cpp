// Restart state of the thin-wall models (ImmersedSurfaceModel::restart_state, docs/coupling.md
// "Restarts"): a prescribed-motion scene runs N coupling windows; a second, identical run does
// the same, then its model is replaced by a fresh one built from the handshake geometry and
// loaded with the first run's restart state (its particles restored as the fluid's restart
// would); both continue M windows and must agree bit for bit (particles, node loads, counters). Also: the state survives a round trip unchanged, and
// a missing or mis-sized array is refused by name.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>

#include "valvefsi/fluid/fluid_solver.hpp"
#include "valvefsi/fluid/geometry.hpp"
#include "valvefsi/fluid/thin_wall/scenes_2d.hpp"
#include "valvefsi/fluid/thin_wall/solver_run_2d.hpp"
#include "valvefsi/fluid/thin_wall/scenes_3d.hpp"
#include "valvefsi/fluid/thin_wall/thin_wall_model.hpp"
#include "valvefsi/fluid/thin_wall/thin_wall_model_3d.hpp"

namespace valvefsi::fluid::thin_wall {
namespace {

constexpr double kWindow = 2e-3;  // s

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

template <int D>
void expect_same_particles(const Particles<D>& a, const Particles<D>& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_TRUE(same_bits(a.id, b.id));
  for (int d = 0; d < D; ++d) {
    EXPECT_TRUE(same_bits(a.position[d], b.position[d])) << "position " << d;
    EXPECT_TRUE(same_bits(a.velocity[d], b.velocity[d])) << "velocity " << d;
    EXPECT_TRUE(same_bits(a.acceleration[d], b.acceleration[d])) << "acceleration " << d;
  }
  EXPECT_TRUE(same_bits(a.density_excess, b.density_excess));
  EXPECT_TRUE(same_bits(a.pressure, b.pressure));
}

template <int D>
void expect_same_surface(const ImmersedSurfaceModel<D>& a, const ImmersedSurfaceModel<D>& b) {
  std::vector<Vec<D>> fa(a.node_count()), fb(b.node_count());
  a.node_forces(fa);
  b.node_forces(fb);
  EXPECT_TRUE(same_bits(fa, fb)) << "node forces";
  EXPECT_EQ(a.counters().corrections, b.counters().corrections);
  EXPECT_EQ(a.counters().leaks, b.counters().leaks);
  EXPECT_EQ(a.counters().rejected_shifts, b.counters().rejected_shifts);
}

void expect_same_state(const std::vector<NamedArray>& a, const std::vector<NamedArray>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].name, b[k].name);
    EXPECT_TRUE(same_bits(a[k].values, b[k].values)) << a[k].name;
  }
}

// One run of a scene: the solver with its model, fed one window of prescribed motion at a time.
template <int D>
struct WindowedRun {
  int before = 8, after = 8;  // windows before and after the restart
  std::unique_ptr<FluidSolver<D>> solver;
  std::function<void(double, std::vector<Vec<D>>&, std::vector<Vec<D>>&)> targets;
  void window(int k) {
    const double end = (k + 1) * kWindow;
    std::vector<Vec<D>> x, v;
    targets(end, x, v);
    solver->immersed_surface()->set_window_target(end, x, v);
    solver->advance_to(end);
  }
};

// The bit-for-bit check shared by 2D and 3D: `make_model` builds a fresh model from the
// handshake geometry, `make_run` a fresh run with one.
template <int D, class MakeModel, class MakeRun>
void check_restart(MakeModel make_model, MakeRun make_run) {
  WindowedRun<D> whole = make_run(make_model());
  WindowedRun<D> restarted = make_run(make_model());
  for (int k = 0; k < whole.before; ++k) {
    whole.window(k);
    restarted.window(k);
  }
  {
    SCOPED_TRACE("the two runs before the restart (the fluid is deterministic)");
    expect_same_particles(whole.solver->particles(), restarted.solver->particles());
  }
  const auto state = whole.solver->immersed_surface()->restart_state();
  ASSERT_TRUE(state.has_value());

  // The fluid restores its particles (rates included) from its own file without re-evaluating
  // them: here its checkpoint stands for that file. Installing a model re-evaluates the
  // rates, so the particles come back from the checkpoint afterwards, and the fresh model
  // from its own checkpoint, taken right after loading the restart state.
  restarted.solver->save_checkpoint();
  auto fresh = make_model();
  fresh->load_restart_state(*state);
  expect_same_state(*state, *fresh->restart_state());  // nothing lost in the round trip
  fresh->save_checkpoint();
  restarted.solver->set_immersed_surface(std::move(fresh));
  restarted.solver->restore_checkpoint();
  expect_same_particles(whole.solver->particles(), restarted.solver->particles());
  expect_same_state(*state, *restarted.solver->immersed_surface()->restart_state());

  for (int k = whole.before; k < whole.before + whole.after; ++k) {
    whole.window(k);
    restarted.window(k);
  }
  EXPECT_EQ(whole.solver->step_count(), restarted.solver->step_count());
  EXPECT_EQ(whole.solver->time(), restarted.solver->time());
  expect_same_particles(whole.solver->particles(), restarted.solver->particles());
  expect_same_surface(*whole.solver->immersed_surface(), *restarted.solver->immersed_surface());
  expect_same_state(*whole.solver->immersed_surface()->restart_state(), *restarted.solver->immersed_surface()->restart_state());
}

TEST(ThinWallRestart, TwoDimensionalModelContinuesBitForBit) {
  OscillatingPlate plate;
  plate.amplitude = 0.01;
  plate.period = 0.05;  // the plate moves 0.6 m/s at most: put-backs and shifting happen
  ThinWallCase2D c = oscillating_plate_box(0.02, plate);
  c.fluid.shifting = 1.0;
  ASSERT_TRUE(c.motion);
  c.motion(0.0, c.walls);
  const ImmersedSurfaceGeometry<2> g = surface_of(c.walls);
  auto make_model = [&] { return std::make_unique<ThinWallModel2D>(g, c.fluid, c.wall_settings); };
  auto make_run = [&](std::unique_ptr<ThinWallModel2D> model) {
    WindowedRun<2> r;
    r.before = r.after = 5;
    r.solver = std::make_unique<FluidSolver<2>>(c.fluid, fill_particles<2>(c.scene, c.fluid), std::vector<PressurePlate<2>>{},
                                                std::move(model));
    r.targets = [&c](double t, std::vector<Vec2>& x, std::vector<Vec2>& v) {
      std::vector<Polyline> walls = c.walls;
      c.motion(t, walls);
      x.clear();
      v.clear();
      for (const Polyline& w : walls) {
        x.insert(x.end(), w.position.begin(), w.position.end());
        v.insert(v.end(), w.velocity.begin(), w.velocity.end());
      }
    };
    return r;
  };
  check_restart<2>(make_model, make_run);
}

TEST(ThinWallRestart, ThreeDimensionalModelContinuesBitForBit) {
  RockingFlap flap;
  flap.period = 0.04;  // up to a third of the rocking angle in the 12 ms run: tip at ~1.7 m/s
  ThinWallCase3D c = rocking_flap_box(0.02, flap);
  c.fluid.sound_speed = 30.0;  // the scene's 40 L / T would be 300 m/s: 10x the steps
  c.fluid.shifting = 1.0;
  ASSERT_TRUE(c.motion);
  {
    std::vector<Vec3> v;
    c.motion(0.0, c.surface.nodes, v);
  }
  auto make_model = [&] { return std::make_unique<ThinWallModel3D>(c.surface, c.fluid, c.wall_settings); };
  auto make_run = [&](std::unique_ptr<ThinWallModel3D> model) {
    WindowedRun<3> r;
    r.before = r.after = 3;  // the flap scene costs 10x the plate's step
    r.solver = std::make_unique<FluidSolver<3>>(c.fluid, fill_particles<3>(c.scene, c.fluid), std::vector<PressurePlate<3>>{},
                                                std::move(model));
    r.targets = [&c](double t, std::vector<Vec3>& x, std::vector<Vec3>& v) { c.motion(t, x, v); };
    return r;
  };
  check_restart<3>(make_model, make_run);
}

TEST(ThinWallRestart, RefusesMissingOrMisSizedArraysByName) {
  ThinWallCase3D c = rocking_flap_box(0.02, RockingFlap{});
  ThinWallModel3D model(c.surface, c.fluid, c.wall_settings);
  auto state = *model.restart_state();
  ThinWallModel3D other(c.surface, c.fluid, c.wall_settings);
  for (auto& a : state)
    if (a.name == "nodes.force") a.values.pop_back();
  try {
    other.load_restart_state(state);
    FAIL() << "a mis-sized array was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'nodes.force'"), std::string::npos) << e.what();
  }
  std::erase_if(state, [](const NamedArray& a) { return a.name == "motion.x1"; });
  try {
    other.load_restart_state(state);
    FAIL() << "a missing array was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'motion.x1'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace valvefsi::fluid::thin_wall
