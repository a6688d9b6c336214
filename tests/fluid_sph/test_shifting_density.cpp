// What a particle shift does to the shifted particle's density (fluid.shifting_density_correction,
// docs/fluid_sph.md "Shifting and density"):
//  - FIELD_AT_NEW_POSITION: on a perturbed lattice carrying a linear density field (a
//    hydrostatic column's), a shifted particle's corrected density is the field at its new
//    position (exact for a linear field: the gradient is renormalised); uncorrected it is off by
//    the field's change over the shift.
//  - SHIFT_CONTINUITY: the change (before smoothing) makes the density the summation density
//    sum_b m W_ab at the new positions to second order in the shift (error / 4 when the shift
//    halves); uncorrected, the error is the first-order change itself. The smoothing keeps a
//    uniform change and damps a particle-scale one.
//  - In a closed box whose blood is pulled into tension by an outward velocity pulse and then
//    rings, shifting every step: the fluid's volume sum m/rho against the box's area.
#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "test_helpers.hpp"
#include "valvefsi/fluid/cell_grid.hpp"
#include "valvefsi/fluid/fluid_solver.hpp"
#include "valvefsi/fluid/geometry.hpp"
#include "valvefsi/fluid/interactions.hpp"
#include "valvefsi/fluid/kernels.hpp"

namespace valvefsi::fluid {
namespace {

using Mode = FluidSettings<2>::ShiftingDensity;

// A free square patch of n x n fluid particles, dp apart, each moved by up to +-0.15 dp, its
// density excess field(x) (kg/m^3), sorted into its grid with the pair loops' scratch set.
struct Patch {
  FluidSettings<2> settings;
  Particles<2> particles;
  CellGrid<2> grid;
  std::array<std::vector<double>, 2> shift;
  double side;

  template <class Field>
  Patch(int n, Field field)
      : settings(make_settings(n)), grid(settings.domain_lower, settings.domain_upper, settings.support_radius(), {false, false}),
        side(n * settings.particle_spacing) {
    const double dp = settings.particle_spacing;
    std::mt19937 random(7);
    std::uniform_real_distribution<double> jitter(-0.15 * dp, 0.15 * dp);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const Vec<2> x{(i + 0.5) * dp + jitter(random), (j + 0.5) * dp + jitter(random)};
        particles.add(x, {0.0f, 0.0f}, static_cast<float>(field(x)), Kind::fluid);
      }
    grid.wrap_and_mark_lost(particles);
    grid.sort(particles);
    update_fluid_pressure<2>(particles, settings);
    compute_fluid_rates<2>(particles, grid, settings);  // grad C, the shift's direction
  }

  static FluidSettings<2> make_settings(int n) {
    FluidSettings<2> s;
    s.particle_spacing = 0.01;
    s.rest_density = 1000.0;
    s.sound_speed = 20.0;
    s.shifting = 1.0;
    s.domain_lower = {-0.1, -0.1};
    s.domain_upper = {n * 0.01 + 0.1, n * 0.01 + 0.1};
    return s;
  }

  // The shifting's direction -grad C, scaled so that the largest shift is `largest` (m).
  void set_shift(double largest) {
    double top = 0.0;
    for (std::size_t i = 0; i < particles.size(); ++i)
      top = std::max<double>(top, std::hypot(particles.kernel_sum_gradient[0][i], particles.kernel_sum_gradient[1][i]));
    for (int d = 0; d < 2; ++d) {
      shift[d].assign(particles.size(), 0.0);
      for (std::size_t i = 0; i < particles.size(); ++i) shift[d][i] = -largest / top * particles.kernel_sum_gradient[d][i];
    }
  }

  std::vector<float> change(Mode mode) {
    settings.shifting_density = mode;
    std::vector<float> out;
    shifting_density_change<2>(particles, grid, settings, {}, shift, out, 0, particles.size());
    return out;
  }

  // Particles whose whole kernel support lies inside the patch.
  bool interior(std::size_t i) const {
    const double margin = settings.support_radius() + 0.2 * settings.particle_spacing;
    for (int d = 0; d < 2; ++d)
      if (particles.position[d][i] < margin || particles.position[d][i] > side - margin) return false;
    return true;
  }

  Vec<2> shifted(std::size_t i) const { return {particles.position[0][i] + shift[0][i], particles.position[1][i] + shift[1][i]}; }
};

TEST(ShiftingDensity, FieldAtNewPositionIsExactForALinearField) {
  // A hydrostatic-like field: 200 kg/m^3 per m along x, 300 along y (rho g / c0^2 of a column
  // at c0 = 0.18 m/s; the size only sets the numbers).
  auto field = [](const Vec<2>& x) { return 200.0 * x[0] + 300.0 * x[1]; };
  Patch patch(30, field);
  patch.set_shift(0.05 * patch.settings.particle_spacing);  // the solver's cap
  const auto corrected = patch.change(Mode::field_gradient);
  const auto kept = patch.change(Mode::keep);
  double worst_corrected = 0.0, worst_kept = 0.0;
  int checked = 0;
  const auto& p = patch.particles;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!patch.interior(i)) continue;
    ++checked;
    const double target = field(patch.shifted(i));
    worst_corrected = std::max(worst_corrected, std::abs(p.density_excess[i] + corrected[i] - target));
    worst_kept = std::max(worst_kept, std::abs(p.density_excess[i] + kept[i] - target));
  }
  spdlog::info("linear field, shift <= 0.05 dp, {} interior particles: |rho - field(new x)| <= {:.3g} corrected, {:.3g} kept",
               checked, worst_corrected, worst_kept);
  ASSERT_GT(checked, 300);
  // Kept: off by grad rho . dr, up to |grad rho| 0.05 dp = 0.18 kg/m^3.
  EXPECT_GT(worst_kept, 0.05);
  // Corrected: exact but for float round-off (positions and densities are floats).
  EXPECT_LT(worst_corrected, 1e-3 * worst_kept);
}

TEST(ShiftingDensity, ContinuityFollowsTheSummationDensityToSecondOrder) {
  Patch patch(30, [](const Vec<2>&) { return 0.0; });
  const auto& p = patch.particles;
  const CubicSplineKernel<2> W(patch.settings.smoothing_length());
  const double mass = patch.settings.particle_mass(), support = patch.settings.support_radius();
  auto summation_density = [&](std::size_t a, bool moved) {
    const Vec<2> xa = moved ? patch.shifted(a) : Vec<2>{p.position[0][a], p.position[1][a]};
    double rho = 0.0;
    for (std::size_t b = 0; b < p.size(); ++b) {
      const Vec<2> xb = moved ? patch.shifted(b) : Vec<2>{p.position[0][b], p.position[1][b]};
      const double r = std::hypot(xa[0] - xb[0], xa[1] - xb[1]);
      if (r < support) rho += mass * W.value(static_cast<float>(r));
    }
    return rho;
  };
  // Largest |rho_sum(new) - rho_sum(old) - change| over the interior, with and without the change.
  auto errors = [&](double largest) {
    patch.set_shift(largest);
    const auto change = patch.change(Mode::continuity);
    double corrected = 0.0, kept = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (!patch.interior(i)) continue;
      const double moved = summation_density(i, true) - summation_density(i, false);
      corrected = std::max(corrected, std::abs(moved - change[i]));
      kept = std::max(kept, std::abs(moved));
    }
    return std::pair{corrected, kept};
  };
  const double dp = patch.settings.particle_spacing;
  const auto [corrected_1, kept_1] = errors(0.05 * dp);
  const auto [corrected_2, kept_2] = errors(0.025 * dp);
  spdlog::info("continuity: |rho_sum(new) - rho|: shift 0.05 dp {:.4g} corrected, {:.4g} kept; 0.025 dp {:.4g}, {:.4g}",
               corrected_1, kept_1, corrected_2, kept_2);
  EXPECT_GT(corrected_1 / corrected_2, 3.5);  // second order: 4
  EXPECT_NEAR(kept_1 / kept_2, 2.0, 0.2);     // first order
  EXPECT_LT(corrected_1, 0.1 * kept_1);
}

TEST(ShiftingDensity, SmoothingKeepsTheMeanAndDampsParticleScaleNoise) {
  // The continuity change is smoothed over the kernel (the shift's divergence is noisy at the
  // particle scale): a uniform change must stay as it is, an alternating +-1 one must fade.
  Patch patch(30, [](const Vec<2>&) { return 0.0; });
  const auto& p = patch.particles;
  std::vector<float> uniform(p.size(), 0.7f), alternating(p.size()), raw;
  for (std::size_t i = 0; i < p.size(); ++i) alternating[i] = (p.id[i] + p.id[i] / 30) % 2 == 0 ? 1.0f : -1.0f;
  smooth_shifting_density_change<2>(p, patch.grid, patch.settings, {}, uniform, raw, 0, p.size());
  smooth_shifting_density_change<2>(p, patch.grid, patch.settings, {}, alternating, raw, 0, p.size());
  double uniform_error = 0.0, alternating_left = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    uniform_error = std::max(uniform_error, std::abs(uniform[i] - 0.7));
    if (patch.interior(i)) alternating_left = std::max<double>(alternating_left, std::abs(alternating[i]));
  }
  spdlog::info("smoothing: uniform 0.7 kept within {:.2g}; a checkerboard of +-1 left at most {:.3f}", uniform_error, alternating_left);
  EXPECT_LT(uniform_error, 1e-6);
  EXPECT_LT(alternating_left, 0.3);
}

// The fluid's volume error 1 - sum m/rho / area after `end` s in a closed square box of blood
// whose centre is pulled apart at t = 0 (radial velocity pulse, peak `speed`).
double box_volume_error(Mode mode, double end) {
  const double L = 0.05, dp = L / 40, R = 0.008, speed = 1.0;
  FluidSettings<2> s = testing::blood_box_settings(L, dp, 10.0);
  s.shifting_density = mode;
  SceneGeometry<2> scene;
  scene.walls.push_back(container_box<2>({0.0, 0.0}, {L, L}));
  const Vec<2> centre{L / 2, L / 2};
  scene.fluid.push_back({{0.0, 0.0}, {L, L}, [&](const Vec<2>& x) {
                           const double dx = x[0] - centre[0], dy = x[1] - centre[1];
                           const double f = speed / R * std::exp(0.5 - (dx * dx + dy * dy) / (2 * R * R));
                           return Vec<2>{f * dx, f * dy};
                         },
                         [](const Vec<2>&) { return 0.0; }});
  FluidSolver<2> solver(s, fill_particles(scene, s));
  const double area = L * L;
  auto volume_error = [&] {
    const auto& p = solver.particles();
    double volume = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.kind[i] == Kind::fluid) volume += s.particle_mass() / (s.rest_density + p.density_excess[i]);
    return 1.0 - volume / area;
  };
  solver.advance_to(end);
  EXPECT_EQ(solver.lost_count(), 0u);
  return volume_error();
}

TEST(ShiftingDensity, BoxVolumeThroughATensionPulse) {
  // The pulse rings for 0.1 s (20 crossings of the box at c0); shifting spreads the particles
  // the tension pulled apart. Kept, the density does not follow and the fluid ends 3.2 % short
  // of its box; corrected by the continuity form, 0.24 % (measured, docs/fluid_sph.md; the field
  // form does not help here: 3.19 %).
  const double kept = box_volume_error(Mode::keep, 0.1);
  const double corrected = box_volume_error(Mode::continuity, 0.1);
  spdlog::info("box, tension pulse: volume error at 0.1 s {:.3f} % kept, {:.3f} % continuity", 100 * kept, 100 * corrected);
  EXPECT_GT(kept, 0.02);
  EXPECT_LT(std::abs(corrected), 0.005);
}

}  // namespace
}  // namespace valvefsi::fluid
