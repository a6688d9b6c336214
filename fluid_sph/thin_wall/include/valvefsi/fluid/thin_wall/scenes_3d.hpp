#pragma once
// The 3D proof scenes of the thin wall (docs/thin-leaflet.md, "3D"), shared by the tests and
// the experiment program; they run on FluidSolver<3> through ThinWallSolverRun3D.
#include <functional>
#include <vector>

#include "valvefsi/fluid/fluid_settings.hpp"
#include "valvefsi/fluid/geometry.hpp"
#include "valvefsi/fluid/immersed_surface.hpp"
#include "valvefsi/fluid/thin_wall/thin_wall_model_3d.hpp"

namespace valvefsi::fluid::thin_wall {

struct ThinWallCase3D {
  FluidSettings<3> fluid;
  ThinWall3DSettings wall_settings;
  SceneGeometry<3> scene;
  ImmersedSurfaceGeometry<3> surface;  // the leaflets at t = 0, as the coupler sends them
  // Prescribed motion: node positions and velocities at a time (the accelerations come from
  // the model's window interpolation). Empty: the surface stays fixed.
  std::function<void(double time, std::vector<Vec3>& x, std::vector<Vec3>& v)> motion;
};

// A flat rectangle origin + s u + t v, s, t in [0, 1], cut into nu x nv cells of two
// triangles each; the normal is u x v (side +1).
ImmersedSurfaceGeometry<3> rectangle_mesh(const Vec3& origin, const Vec3& u, const Vec3& v, int nu, int nv);
// A flat disk of the given radius about `centre` in the plane x = centre[0] (normal +x),
// rings about `spacing` apart.
ImmersedSurfaceGeometry<3> disk_mesh(const Vec3& centre, double radius, double spacing);
// The quarter y >= 0, z >= 0 of such a disk: ring k has k + 1 nodes from the +y to the +z
// axis, so its edges on the planes y = 0 and z = 0 carry nodes that the planes' images share.
ImmersedSurfaceGeometry<3> quarter_disk_mesh(const Vec3& centre, double radius, double spacing);

// A tank [0, 0.5] x [0, width] x [0, ...] of water, z up, split at x = 0.25 m by a thin
// membrane (normal -x: side +1 is the left), water level left_level on the left and
// right_level on the right, hydrostatic at rest. gap = 0: the membrane is buried 3 dp into
// the floor; gap > 0: its lower free edge stands `gap` above the floor. mirror = false: side
// walls at y = 0 and y = width, the membrane buried 3 dp into them; mirror = true: mirror
// planes there instead and the membrane ends on them (the sector's symmetry planes).
ThinWallCase3D two_level_tank_3d(double dp, double left_level, double right_level, double width, double gap, bool mirror);

// A closed cube [-L/2, L/2]^3 of water (no gravity) with a thin disk of radius a in the
// plane x = X(t) = -A cos(omega t), oscillating normal to itself from rest. Potential-flow
// added mass of a disk in unbounded fluid: (8/3) rho a^3.
struct OscillatingDisk {
  double radius = 0.05;     // a (m)
  double amplitude = 0.004; // A (m)
  double period = 0.5;      // s
  double box = 0.3;         // L (m)
  double viscosity = 1e-3;  // Pa s
  // Only the quarter y >= 0, z >= 0 with mirror planes at y = 0 and z = 0 (a quarter of the
  // particles; the force on the whole disk is 4x the quarter's).
  bool quarter = false;
};
ThinWallCase3D oscillating_disk_box(double dp, const OscillatingDisk& disk);

// A flap: a square plate of side b standing on the floor of a closed box of water (no
// gravity), attached along its lower edge (buried 3 dp into the floor) and spanning the box's
// width into its side walls, rocked about that edge by angle theta(t) = theta0 sin^2(pi t/T).
struct RockingFlap {
  double height = 0.1;       // b (m)
  double width = 0.1;        // the box's width (y) (m)
  double max_angle = 0.35;   // theta0 (rad)
  double period = 0.5;       // T (s)
  double box_length = 0.3;   // along x (m)
  double box_height = 0.15;  // along z (m)
};
ThinWallCase3D rocking_flap_box(double dp, const RockingFlap& flap);

}  // namespace valvefsi::fluid::thin_wall
