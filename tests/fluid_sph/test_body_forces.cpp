// The wall loads booked inside the pair loop (compute_fluid_rates with body forces: the
// reaction of each fluid-wall pair term on the wall's body) equal those of the separate pass
// over the wall particles (compute_body_forces), to float round-off: in 3D with a mirror plane
// (its fluid images push on the real walls too) and in the 2D dam break with artificial
// viscosity, with the fluid in motion so the pressure, viscous and artificial terms all count.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "valvefsi/fluid/interactions.hpp"
#include "valvefsi/fluid/kernels.hpp"
#include "valvefsi/fluid/standard_scenes.hpp"

namespace valvefsi::fluid {
namespace {

template <int D>
double norm(const Vec<D>& v) {
  double s = 0;
  for (double x : v) s += x * x;
  return std::sqrt(s);
}

template <int D>
void expect_booked_equals_direct(const FluidSolver<D>& solver) {
  Particles<D> p = solver.particles();  // state after the last step, wall state included
  const auto& s = solver.settings();
  const auto direct = compute_body_forces<D>(p, solver.grid(), s, 1, true);
  std::vector<Vec<D>> booked(1);
  compute_fluid_rates<D>(p, solver.grid(), s, {}, &booked, true);
  ASSERT_GT(norm<D>(direct[0]), 0.0);
  Vec<D> difference{};
  for (int d = 0; d < D; ++d) difference[d] = booked[0][d] - direct[0][d];
  EXPECT_LT(norm<D>(difference), 1e-5 * norm<D>(direct[0]))
      << "direct " << direct[0][0] << ", " << direct[0][1] << "; booked " << booked[0][0] << ", " << booked[0][1];
}

// The 3D tank with a mirror plane (fluid at y > 0.5) in a shear flow, after `steps` steps.
FluidSolver<3> sheared_tank_with_mirror_plane(int steps) {
  auto tank = still_tank_3d(3000);
  auto& s = tank.settings;
  s.mirror_planes.push_back({{0.0, 0.5, 0.0}, {0.0, 1.0, 0.0}});
  Particles<3> particles = fill_particles(tank.scene, s);
  for (std::size_t i = 0; i < particles.size(); ++i) {
    if (particles.kind[i] != Kind::fluid) continue;
    const double x = particles.position[0][i], z = particles.position[2][i];
    particles.velocity[0][i] = static_cast<float>(0.5 * std::sin(std::numbers::pi * z));
    particles.velocity[2][i] = static_cast<float>(-0.5 * std::sin(0.5 * std::numbers::pi * x));
    particles.viscous_velocity[0][i] = particles.velocity[0][i];
    particles.viscous_velocity[2][i] = particles.velocity[2][i];
  }
  FluidSolver<3> solver(s, std::move(particles));
  for (int k = 0; k < steps; ++k) solver.step();
  return solver;
}

TEST(BodyForces, BookedInPairLoopEqualsWallPass3DWithMirrorPlane) {
  const FluidSolver<3> solver = sheared_tank_with_mirror_plane(5);
  ASSERT_GT(solver.particles().count(Kind::mirror_fluid), 0u);
  expect_booked_equals_direct(solver);
}

// The vectorised pair loop leaves out neighbours by bounding boxes and skips a neighbour for a
// vector of lanes all beyond its support (session 14). Neither may drop a pair within the
// support: the continuity rate and the kernel sum of every fluid particle equal a brute-force
// sum over all pairs (walls and mirror images included) in double precision, to float
// round-off of the sum of the terms' magnitudes.
TEST(BodyForces, PairLoopRatesEqualABruteForceSumOverAllPairs3D) {
  const FluidSolver<3> solver = sheared_tank_with_mirror_plane(3);
  ASSERT_GT(solver.particles().count(Kind::mirror_fluid), 0u);
  Particles<3> p = solver.particles();
  auto settings = solver.settings();
  settings.density_diffusion = 0.0;  // density rate = continuity alone
  settings.shifting = 1.0;           // the pair loop then sums the kernel too
  compute_fluid_rates<3>(p, solver.grid(), settings, {});
  const double mass = settings.particle_mass();
  const double support = settings.support_radius();
  std::size_t checked = 0, with_dropped_pairs = 0;
  with_kernel<3>(settings.kernel, settings.smoothing_length(), [&](const auto& W) {
    for (std::size_t a = 0; a < p.size(); ++a) {
      if (p.kind[a] != Kind::fluid) continue;
      double continuity = 0, continuity_scale = 0, kernel_sum = 0;
      for (std::size_t b = 0; b < p.size(); ++b) {
        if (p.kind[b] == Kind::lost) continue;
        double r2 = 0, vdx = 0;
        for (int d = 0; d < 3; ++d) {
          const double dx = static_cast<double>(p.local_position[d][a]) - p.local_position[d][b];
          r2 += dx * dx;
          vdx += (static_cast<double>(p.velocity[d][a]) - p.velocity[d][b]) * dx;
        }
        if (r2 >= support * support) continue;
        const auto r = static_cast<float>(std::sqrt(r2));
        continuity += mass * vdx * W.gradient_factor(r);
        continuity_scale += std::abs(mass * vdx * W.gradient_factor(r));
        kernel_sum += mass * W.value(r) * p.inverse_density[b];
      }
      ++checked;
      const bool continuity_off = std::abs(p.density_rate[a] - continuity) > 1e-4 * continuity_scale + 1e-12;
      const bool kernel_sum_off = std::abs(p.kernel_sum[a] - kernel_sum) > 1e-5 * kernel_sum;
      if (continuity_off || kernel_sum_off) ++with_dropped_pairs;
      if (with_dropped_pairs == 1 && (continuity_off || kernel_sum_off))
        ADD_FAILURE() << "particle " << a << ": density rate " << p.density_rate[a] << " against " << continuity
                      << ", kernel sum " << p.kernel_sum[a] << " against " << kernel_sum;
    }
  });
  EXPECT_GT(checked, 1000u);
  EXPECT_EQ(with_dropped_pairs, 0u);
}

TEST(BodyForces, BookedInPairLoopEqualsWallPassDamBreak2D) {
  auto db = dam_break_2d(0.04);
  FluidSolver<2> solver(db.settings, fill_particles(db.scene, db.settings));
  solver.advance_to(0.3);  // the column is collapsing: pressure, shear and compression
  expect_booked_equals_direct(solver);
}

}  // namespace
}  // namespace valvefsi::fluid
