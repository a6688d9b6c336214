#include "valvefsi/fluid/thin_wall/scenes_2d.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace valvefsi::fluid::thin_wall {

ThinWallCase2D two_level_tank(double dp, double left_level, double right_level, double gap) {
  ThinWallCase2D c;
  auto& s = c.fluid;
  s.particle_spacing = dp;
  s.rest_density = 1000.0;
  s.dynamic_viscosity = 1e-3;
  s.artificial_viscosity = 0.02;  // damps the start-up's acoustic transient
  s.gravity = {0.0, -9.81};
  s.sound_speed = 15.0 * std::sqrt(9.81 * std::max(left_level, right_level));
  s.domain_lower = {-0.2, -0.2};
  s.domain_upper = {1.2, 1.5};
  c.scene.walls.push_back(container_box<2>({0.0, 0.0}, {1.0, 1e9}));
  c.scene.fluid.push_back({{0.0, 0.0}, {0.5, left_level}, {}, {}});
  c.scene.fluid.push_back({{0.5, 0.0}, {1.0, right_level}, {}, {}});
  const double bottom = gap > 0 ? gap : -3.0 * dp;
  c.walls.push_back(Polyline::at_rest({{0.5, bottom}, {0.5, 1.2}}));
  return c;
}

ThinWallCase2D two_level_tank_with_joint(double dp, double left_level, double right_level, double joint, double gap) {
  ThinWallCase2D c = two_level_tank(dp, left_level, right_level, 0.0);
  c.walls.clear();
  c.walls.push_back(Polyline::at_rest({{0.5, -3.0 * dp}, {0.5, joint - gap / 2}}));
  c.walls.push_back(Polyline::at_rest({{0.5, joint + gap / 2}, {0.5, 1.2}}));
  return c;
}

ThinWallCase2D oscillating_plate_box(double dp, const OscillatingPlate& plate) {
  ThinWallCase2D c;
  auto& s = c.fluid;
  s.particle_spacing = dp;
  s.rest_density = 1000.0;
  s.dynamic_viscosity = plate.viscosity;
  const double omega = 2.0 * std::numbers::pi / plate.period;
  const double speed = plate.amplitude * omega;
  // Edge speeds reach a few times the plate's; c0 keeps the box's acoustic modes far above
  // the forcing (L / c0 << period).
  s.sound_speed = std::max(20.0 * speed, 40.0 * plate.box_length / plate.period);
  const double L = plate.box_length, H = plate.box_height;
  s.domain_lower = {-L / 2 - 0.2 * L, -H / 2 - 0.2 * H};
  s.domain_upper = {L / 2 + 0.2 * L, H / 2 + 0.2 * H};
  c.scene.walls.push_back(container_box<2>({-L / 2, -H / 2}, {L / 2, H / 2}));
  c.scene.fluid.push_back({{-L / 2, -H / 2}, {L / 2, H / 2}, {}, [](const Vec<2>&) { return 0.0; }});
  // Lattice offset so that the plate's line x = 0 lies half-way between particle columns.
  c.scene.lattice_origin = {0.0, 0.0};
  const double half = plate.plate_width / 2;
  c.walls.push_back(Polyline::at_rest({{-plate.amplitude, -half}, {-plate.amplitude, half}}));
  const double A = plate.amplitude;
  c.motion = [A, omega, half](double t, std::vector<Polyline>& walls) {
    // X = -A cos(wt): starts at rest (no impulsive start), centred after the first period.
    const double x = -A * std::cos(omega * t), v = A * omega * std::sin(omega * t), a = A * omega * omega * std::cos(omega * t);
    Polyline& w = walls.front();
    w.position = {{x, -half}, {x, half}};
    w.velocity = {{v, 0.0}, {v, 0.0}};
    w.acceleration = {{a, 0.0}, {a, 0.0}};
  };
  return c;
}

double ClosingFlaps::half_gap(double t) const {
  const double s = std::clamp(t / duration, 0.0, 1.0);
  return end_half_gap + (start_half_gap - end_half_gap) * (1.0 - s * s * (3.0 - 2.0 * s));
}

double ClosingFlaps::closing_speed(double t) const {
  const double s = std::clamp(t / duration, 0.0, 1.0);
  return (start_half_gap - end_half_gap) * 6.0 * s * (1.0 - s) / duration;
}

ThinWallCase2D closing_flaps_box(double dp, const ClosingFlaps& flaps) {
  ThinWallCase2D c;
  auto& s = c.fluid;
  s.particle_spacing = dp;
  s.rest_density = 1000.0;
  s.dynamic_viscosity = 1e-3;
  // The squeezed water leaves the gap at about V b / (2 d); c0 keeps it below 0.1 c0 down to
  // d = dp, where the last particles leave.
  const double top_speed = 1.5 * (flaps.start_half_gap - flaps.end_half_gap) / flaps.duration;
  s.sound_speed = std::max(20.0, 10.0 * top_speed * flaps.flap_length / (2.0 * dp));
  s.shifting = 1.0;
  const double L = flaps.box;
  s.domain_lower = {-0.7 * L, -0.7 * L};
  s.domain_upper = {0.7 * L, 0.7 * L};
  c.scene.walls.push_back(container_box<2>({-L / 2, -L / 2}, {L / 2, L / 2}));
  c.scene.fluid.push_back({{-L / 2, -L / 2}, {L / 2, L / 2}, {}, [](const Vec<2>&) { return 0.0; }});
  const double half = flaps.flap_length / 2;
  // Left flap runs upwards, right flap downwards: side +1 of both faces away from the gap.
  c.walls.push_back(Polyline::at_rest({{-flaps.start_half_gap, -half}, {-flaps.start_half_gap, half}}));
  c.walls.push_back(Polyline::at_rest({{flaps.start_half_gap, half}, {flaps.start_half_gap, -half}}));
  c.motion = [flaps, half](double t, std::vector<Polyline>& walls) {
    const double d = flaps.half_gap(t), v = flaps.closing_speed(t);
    walls[0].position = {{-d, -half}, {-d, half}};
    walls[0].velocity = {{v, 0.0}, {v, 0.0}};
    walls[1].position = {{d, half}, {d, -half}};
    walls[1].velocity = {{-v, 0.0}, {-v, 0.0}};
  };
  return c;
}

}  // namespace valvefsi::fluid::thin_wall
