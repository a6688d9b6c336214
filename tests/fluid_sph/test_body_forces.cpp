// The wall loads booked inside the pair loop (compute_fluid_rates with body forces: the
// reaction of each fluid-wall pair term on the wall's body) equal those of the separate pass
// over the wall particles (compute_body_forces), to float round-off: in 3D with a mirror plane
// (its fluid images push on the real walls too) and in the 2D dam break with artificial
// viscosity, with the fluid in motion so the pressure, viscous and artificial terms all count.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "valvefsi/fluid/interactions.hpp"
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

TEST(BodyForces, BookedInPairLoopEqualsWallPass3DWithMirrorPlane) {
  auto tank = still_tank_3d(3000);
  auto& s = tank.settings;
  s.mirror_planes.push_back({{0.0, 0.5, 0.0}, {0.0, 1.0, 0.0}});  // fluid at y > 0.5
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
  for (int k = 0; k < 5; ++k) solver.step();
  ASSERT_GT(solver.particles().count(Kind::mirror_fluid), 0u);
  expect_booked_equals_direct(solver);
}

TEST(BodyForces, BookedInPairLoopEqualsWallPassDamBreak2D) {
  auto db = dam_break_2d(0.04);
  FluidSolver<2> solver(db.settings, fill_particles(db.scene, db.settings));
  solver.advance_to(0.3);  // the column is collapsing: pressure, shear and compression
  expect_booked_equals_direct(solver);
}

}  // namespace
}  // namespace valvefsi::fluid
