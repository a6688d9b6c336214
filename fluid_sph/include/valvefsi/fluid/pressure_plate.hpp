#pragma once
// A pressure plate: a rigid piston of wall particles that moves along its normal, pushed
// into the fluid by a prescribed pressure and held back by the fluid's force on it,
//   m_plate du/dt = p_prescribed(t) A + F_fluid . n.
// This is how the reference applies its pressure boundary conditions (two rigid plates,
// section 2.3); the particles next to the plate then carry a flat velocity profile.
#include <functional>
#include <limits>

#include "valvefsi/fluid/particles.hpp"

namespace valvefsi::fluid {

template <int D>
struct PressurePlate {
  Vec<D> normal{};        // unit vector pointing from the plate into the fluid
  double area = 0.0;      // wetted area (m^2; m per unit depth in 2D)
  double mass = 0.0;      // kg (per unit depth in 2D)
  std::function<double(double)> pressure;  // prescribed pressure at time t (Pa)
  // Displacements the plate may reach (m); beyond them the solver stops (PlateTravelExceeded).
  double min_displacement = -std::numeric_limits<double>::infinity();
  double max_displacement = std::numeric_limits<double>::infinity();

  // State along the normal.
  double displacement = 0.0;  // m
  double velocity = 0.0;      // m/s
  double acceleration = 0.0;  // m/s^2
  Vec<D> fluid_force{};       // last force of the fluid on the plate (N)

  // The fluid force includes the background pressure on the wetted face; the prescribed
  // (gauge) pressure is raised by the same amount so the two balance.
  double acceleration_at(double t, const Vec<D>& force, double background_pressure) const {
    double normal_force = 0.0;
    for (int d = 0; d < D; ++d) normal_force += force[d] * normal[d];
    return ((pressure(t) + background_pressure) * area + normal_force) / mass;
  }
};

}  // namespace valvefsi::fluid
