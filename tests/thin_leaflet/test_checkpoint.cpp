// In-memory checkpoint of the fluid with a thin wall (implicit coupling, docs/coupling.md): a
// window run again after restore_checkpoint() must give the node loads of its first run bit
// for bit, whether the window before it ran once or was itself repeated. Otherwise the
// coupler's fixed-point iterations see a fluid whose answer to the same motion changes
// between passes, and no acceleration converges (issue 8, docs/thin-leaflet.md "Coupled runs").
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <functional>
#include <memory>
#include <vector>

#include "valvefsi/fluid/fluid_solver.hpp"
#include "valvefsi/fluid/cell_grid.hpp"
#include "valvefsi/fluid/geometry.hpp"
#include "valvefsi/fluid/interactions.hpp"
#include "valvefsi/fluid/thin_wall/scenes_2d.hpp"
#include "valvefsi/fluid/thin_wall/solver_run_2d.hpp"
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
  const ImmersedSurfaceGeometry<2> g = surface_of(c->walls);
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

// The loads of one step depend continuously on the motion: end positions moved by 1 to 64 units
// in the last place (~1e-18 to 1e-16 m) change the node loads of each of three steps by round-off only.
// (Over a whole window of ~120 steps the same nudge changes the window-averaged loads by ~1 %:
// the particles' float state amplifies it, docs/thin-leaflet.md "Coupled runs".)
TEST(ThinWallCheckpoint, TwoDimensionalStepLoadsAreContinuousInTheMotion) {
  CoupledFluid<2> run = plate_run();
  for (int k = 0; k < 3; ++k) run.pass(k, false, false);
  const double end = 4 * run.window_size;
  std::vector<std::vector<std::vector<Vec2>>> loads;
  for (int nudge : {0, 1, 2, 3, 5, 8, 13, 21, 34, 64}) {
    if (nudge == 0) run.solver->save_checkpoint();
    else run.solver->restore_checkpoint();
    std::vector<Vec2> x, v;
    run.targets(end, x, v);
    for (auto& xj : x)
      for (int d = 0; d < 2; ++d)
        for (int u = 0; u < nudge; ++u) xj[d] = std::nextafter(xj[d], 1.0);
    run.solver->immersed_surface()->set_window_target(end, x, v);
    loads.emplace_back();
    for (int step = 0; step < 3; ++step) {
      run.solver->step();
      std::vector<Vec2> f(run.solver->immersed_surface()->node_count());
      run.solver->immersed_surface()->node_forces(f);
      loads.back().push_back(f);
    }
  }
  for (std::size_t k = 1; k < loads.size(); ++k)
    for (int step = 0; step < 3; ++step) {
      double diff = 0.0, norm = 0.0;
      for (std::size_t j = 0; j < loads[0][step].size(); ++j)
        for (int d = 0; d < 2; ++d) {
          diff += std::pow(loads[k][step][j][d] - loads[0][step][j][d], 2);
          norm += std::pow(loads[0][step][j][d], 2);
        }
      ASSERT_GT(norm, 0.0);
      EXPECT_LT(std::sqrt(diff / norm), 1e-10) << "nudge " << k << ", step " << step;
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

// A "lively" field for the continuity tests: a block of fluid jittered off its lattice (no
// symmetry), with random velocities and densities, in a domain of +-2.5 half-widths.
template <int D>
std::pair<FluidSettings<D>, Particles<D>> lively_field(double half_width, unsigned seed) {
  FluidSettings<D> s;
  s.particle_spacing = 0.005;
  s.sound_speed = 20.0;
  s.artificial_viscosity = 0.02;
  s.gravity[D - 1] = -9.81;
  for (int d = 0; d < D; ++d) {
    s.domain_lower[d] = -half_width * (D == 2 ? 2.0 : 1.5);
    s.domain_upper[d] = half_width * (D == 2 ? 2.0 : 1.5);
  }
  SceneGeometry<D> scene;
  Vec<D> lower, upper;
  for (int d = 0; d < D; ++d) lower[d] = -half_width, upper[d] = half_width;
  scene.fluid.push_back({lower, upper, {}, [](const Vec<D>&) { return 0.0; }});
  Particles<D> base = fill_particles<D>(scene, s);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (std::size_t i = 0; i < base.size(); ++i) {
    for (int d = 0; d < D; ++d) {
      base.position[d][i] += 0.3 * s.particle_spacing * u(rng);  // no lattice symmetry
      base.velocity[d][i] = 0.2f * u(rng);
      base.viscous_velocity[d][i] = base.velocity[d][i];
    }
    base.density_excess[i] = 2.0f * u(rng);
  }
  return {s, base};
}

// The wall's rates on every particle (by particle id) after its nodes moved by `ulps` ulps.
template <int D, class Model>
std::vector<double> rates_after_nudge(const FluidSettings<D>& s, const Particles<D>& base,
                                      const ImmersedSurfaceGeometry<D>& g, int ulps) {
  Particles<D> p = base;
  CellGrid<D> grid(s.domain_lower, s.domain_upper, s.support_radius(), s.periodic);
  grid.wrap_and_mark_lost(p);
  grid.sort(p);
  Model model(g, s, {});
  std::vector<Vec<D>> x1 = g.nodes, v1(g.nodes.size(), Vec<D>{});
  for (auto& x : x1)
    for (int d = 0; d < D; ++d)
      for (int k = 0; k < ulps; ++k) x[d] = std::nextafter(x[d], 1.0);
  model.set_window_target(0.002, x1, v1);
  model.move_to(0.002);
  model.classify(p);
  update_fluid_pressure<D>(p, s);
  model.update_surface_states(p, grid);
  for (int d = 0; d < D; ++d) std::fill(p.acceleration[d].begin(), p.acceleration[d].end(), 0.0f);
  model.add_surface_rates(p);
  std::vector<double> a(D * p.size());
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int d = 0; d < D; ++d) a[D * p.id[i] + static_cast<std::size_t>(d)] = p.acceleration[d][i];
  return a;
}

// Moves the wall by 1-16 ulps and expects no rate to change by more than `bound` of the largest.
template <int D, class Model>
void expect_rates_continuous(const FluidSettings<D>& s, const Particles<D>& base, const ImmersedSurfaceGeometry<D>& g,
                             double bound) {
  const auto a0 = rates_after_nudge<D, Model>(s, base, g, 0);
  double scale = 0.0;
  for (const double v : a0) scale = std::max(scale, std::abs(v));
  ASSERT_GT(scale, 0.0);
  for (int ulps = 1; ulps <= 16; ++ulps) {
    const auto a = rates_after_nudge<D, Model>(s, base, g, ulps);
    double worst = 0.0;
    std::size_t at = 0;
    for (std::size_t k = 0; k < a.size(); ++k)
      if (std::abs(a[k] - a0[k]) > worst) worst = std::abs(a[k] - a0[k]), at = k / D;
    std::printf("%dD continuity: %2d ulps: largest change %.3g (%.3g of the largest rate %.3g), particle id %zu\n", D,
                ulps, worst, worst / scale, scale, at);
    EXPECT_LT(worst, bound * scale) << ulps << " ulps";
  }
}

// The wall's rates on the fluid barely move when the wall moves by 1 to 16 ulps, also for
// particles beyond a free end, whose virtual lattice has a column on the ray through the end
// node: that column's shadow test flipped with round-off (jumps of 5-10 % of the largest
// acceleration here at every nudge, ~4 % of the 2D valve's loads, issue 8). Two leaflets with
// four free ends in a lively field. A smaller jump (0.2 %, at 2 of the 16 nudges) came from a
// ray through an interior node slipping between its two segments by round-off (the segment
// test now has a margin along the wall); now no change at all: the bound is 0.1 %.
TEST(ThinWallContinuity, RatesAreContinuousInTheWallPositionAtFreeEnds) {
  const auto [s, base] = lively_field<2>(0.05, 11);
  ImmersedSurfaceGeometry<2> g;
  g.nodes = {{-0.0301, -0.0199}, {-0.0101, 0.0003}, {-0.0049, 0.0201}, {0.0302, 0.0148}, {0.0099, -0.0152}};
  g.cells = {0, 1, 1, 2, 3, 4};
  g.node_thickness.assign(5, 2.5e-4);
  expect_rates_continuous<2, ThinWallModel2D>(s, base, g, 1e-3);
}

// The same in 3D (docs/thin-leaflet.md, "3D", grazing ray): beyond a free edge the virtual
// lattice has points whose segment from the particle only grazes the edge (the ray through the
// closest point, and with the lattice aligned to the edge the whole sheet through it); asked of
// the crossing test they switch on or off with round-off. Two tilted leaflets (3 x 3 nodes,
// eight triangles each, every edge of the outline free) in a lively field, moved by 1-16 ulps.
TEST(ThinWallContinuity, ThreeDimensionalRatesAreContinuousInTheWallPositionAtFreeEdges) {
  const auto [s, base] = lively_field<3>(0.04, 17);
  ImmersedSurfaceGeometry<3> g;
  g.nodes_per_cell = 3;
  // Leaflet k: 3 x 3 nodes on a tilted, slightly warped square of side ~0.03 m.
  const std::array<Vec3, 2> origin{Vec3{-0.0251, -0.0149, -0.0203}, Vec3{0.0049, -0.0102, 0.0051}};
  const std::array<Vec3, 2> along{Vec3{0.0151, 0.0012, 0.0031}, Vec3{0.0009, 0.0149, -0.0021}};
  const std::array<Vec3, 2> across{Vec3{-0.0019, 0.0148, 0.0023}, Vec3{0.0013, 0.0027, 0.0152}};
  for (int k = 0; k < 2; ++k) {
    const auto first = static_cast<std::uint32_t>(g.nodes.size());
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        Vec3 x;
        for (int d = 0; d < 3; ++d) x[d] = origin[k][d] + i * along[k][d] + j * across[k][d];
        x[2] += 7e-4 * (i - 1) * (j - 1);  // warp: no two triangles coplanar
        g.nodes.push_back(x);
      }
    for (std::uint32_t i = 0; i < 2; ++i)
      for (std::uint32_t j = 0; j < 2; ++j) {
        const std::uint32_t a = first + 3 * i + j, b = a + 3, c = a + 1, d = a + 4;
        g.cells.insert(g.cells.end(), {a, b, d, a, d, c});
      }
  }
  g.node_thickness.assign(g.nodes.size(), 2.5e-4);
  expect_rates_continuous<3, ThinWallModel3D>(s, base, g, 1e-2);
}

}  // namespace
}  // namespace valvefsi::fluid::thin_wall
