#pragma once
// Scenes shared by the verification tests, the benchmarks and the examples, built in code
// so that a test states its whole set-up in one place.
#include "valvefsi/fluid/fluid_solver.hpp"
#include "valvefsi/fluid/geometry.hpp"

namespace valvefsi::fluid {

// 2D dam break: a water column `width` wide and `height` high against the left wall of a
// tank `tank_length` long (Martin & Moyce 1952 with width 1 m, height 2 m, tank 4 m).
// Water, Wendland C2, delta = 0.1, artificial viscosity 0.02, c0 = 20 sqrt(g H), CFL 0.2,
// h = sqrt(2) dp: the settings DualSPHysics' yardstick run used.
struct DamBreak2D {
  FluidSettings<2> settings;
  SceneGeometry<2> scene;
};
DamBreak2D dam_break_2d(double particle_spacing, double width = 1.0, double height = 2.0, double tank_length = 4.0);

// 3D box of water at rest under gravity in a closed tank, about `particle_count` particles.
struct StillTank3D {
  FluidSettings<3> settings;
  SceneGeometry<3> scene;
};
StillTank3D still_tank_3d(long particle_count);

}  // namespace valvefsi::fluid
