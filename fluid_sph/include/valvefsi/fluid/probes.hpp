#pragma once
// Measurements on the particle field: the quantities the reference monitors (pressure at
// points, flow rate through cross-sections, maximum velocity on a plane) plus totals.
#include <vector>

#include "valvefsi/fluid/fluid_solver.hpp"

namespace valvefsi::fluid {

// Pressure at x, Shepard-interpolated from the fluid particles within one kernel support
// (gauge: without the background pressure; Pa); 0 if no fluid particle is that close.
template <int D>
double pressure_at(const FluidSolver<D>& solver, const Vec<D>& x);

// A plane through `point` with unit `normal`, limited to distance `radius` from the point
// (infinite if radius <= 0). Particles count as on the plane within half a spacing of it.
template <int D>
struct ProbePlane {
  Vec<D> point{};
  Vec<D> normal{};
  double radius = 0.0;
};

// Volume flow rate through the plane along its normal (m^3/s; m^2/s in 2D):
// sum over the fluid particles in the slab of thickness dp of (v . n) V / dp.
template <int D>
double flow_rate(const FluidSolver<D>& solver, const ProbePlane<D>& plane);

// Largest fluid speed in the slab of thickness dp around the plane (m/s).
template <int D>
double max_speed_on_plane(const FluidSolver<D>& solver, const ProbePlane<D>& plane);

// Kinetic energy of the fluid (J; J/m in 2D).
template <int D>
double kinetic_energy(const FluidSolver<D>& solver);

}  // namespace valvefsi::fluid
