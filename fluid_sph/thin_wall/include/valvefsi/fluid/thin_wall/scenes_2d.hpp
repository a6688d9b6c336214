#pragma once
// The 2D proof scenes of the thin wall (docs/thin-leaflet.md), shared by tests and the
// experiment program; they run on FluidSolver<2> through ThinWallSolverRun2D.
#include <functional>
#include <vector>

#include "valvefsi/fluid/fluid_settings.hpp"
#include "valvefsi/fluid/geometry.hpp"
#include "valvefsi/fluid/thin_wall/polyline.hpp"
#include "valvefsi/fluid/thin_wall/two_sided_wall.hpp"

namespace valvefsi::fluid::thin_wall {

struct ThinWallCase2D {
  FluidSettings<2> fluid;
  ThinWallSettings wall_settings;
  double coaptation_distance = 0.0;  // m; ThinWallModel2D's bridge between free ends (0: off)
  SceneGeometry<2> scene;      // rigid tank walls and fluid blocks (fill_particles)
  std::vector<Polyline> walls;  // the thin walls (leaflets) at t = 0
  // Prescribed motion: sets every wall's node positions and velocities at a time (the
  // accelerations come from the model's window interpolation). Empty: the walls stay fixed.
  std::function<void(double time, std::vector<Polyline>& walls)> motion;
};

// A 1 m wide tank of water split at x = 0.5 m by a vertical thin wall reaching 1.2 m, water
// level left_level on the left and right_level on the right, both hydrostatic at rest.
// gap = 0: the wall is buried 3 dp into the floor (attachment line); gap > 0: its lower free
// end stands `gap` above the floor. The wall's nodes run upwards, so side +1 is the left.
ThinWallCase2D two_level_tank(double dp, double left_level, double right_level, double gap);

// The same tank with the dividing wall in two pieces that nearly meet: a lower one from the
// floor (buried 3 dp) to y = joint - gap / 2 and an upper one from y = joint + gap / 2 to
// 1.2 m, both running upwards. Their facing ends are free ends `gap` apart (a closed 2D
// valve's tips); set the case's coaptation_distance above gap to join them for the fluid.
ThinWallCase2D two_level_tank_with_joint(double dp, double left_level, double right_level, double joint, double gap);

// A closed box [-L/2, L/2] x [-H/2, H/2] full of water (no gravity) with a plate of width b
// along y at x = X(t) = -A cos(omega t), oscillating normal to itself (from rest).
struct OscillatingPlate {
  double plate_width = 0.1;      // b (m)
  double amplitude = 0.002;      // A (m)
  double period = 0.5;           // 2 pi / omega (s)
  double box_length = 0.4;       // L, along the motion (m)
  double box_height = 0.4;       // H, along the plate (m)
  double viscosity = 1e-3;       // mu (Pa s)
};
ThinWallCase2D oscillating_plate_box(double dp, const OscillatingPlate& plate);

// Coaptation: two parallel flaps of length b (along y, centred on y = 0) at x = -d(t) and
// x = +d(t) in a closed box [-L/2, L/2]^2 full of water (no gravity) close onto each other:
// d goes from d0 to d_min along a smooth step over `duration` (zero speed at both ends), so
// the water between them must leave along the gap, through its two open ends.
struct ClosingFlaps {
  double flap_length = 0.1;  // b (m)
  double start_half_gap = 0.03;  // d0 (m)
  double end_half_gap = 0.002;   // d_min (m)
  double duration = 0.5;     // s
  double box = 0.3;          // L (m)
  double half_gap(double t) const;
  double closing_speed(double t) const;  // -dd/dt (m/s)
};
ThinWallCase2D closing_flaps_box(double dp, const ClosingFlaps& flaps);

}  // namespace valvefsi::fluid::thin_wall
