#include "valvefsi/fluid/standard_scenes.hpp"

#include <cmath>

namespace valvefsi::fluid {

DamBreak2D dam_break_2d(double dp, double width, double height, double tank_length) {
  DamBreak2D db;
  auto& s = db.settings;
  s.particle_spacing = dp;
  s.smoothing_length_ratio = std::sqrt(2.0);
  s.kernel = KernelType::wendland_c2;
  s.rest_density = 1000.0;
  s.dynamic_viscosity = 0.0;
  s.gravity = {0.0, -9.81};
  s.sound_speed = 20.0 * std::sqrt(9.81 * height);
  s.density_diffusion = 0.1;
  s.artificial_viscosity = 0.02;
  s.cfl = 0.2;
  const double margin = 4.0 * s.support_radius();
  s.domain_lower = {-margin, -margin};
  s.domain_upper = {tank_length + margin, 3.0 * height + margin};  // room for the run-up jet on the far wall
  db.scene.walls.push_back(container_box<2>({0.0, 0.0}, {tank_length, 1e9}));
  db.scene.fluid.push_back({{0.0, 0.0}, {width, height}, {}, {}});
  return db;
}

StillTank3D still_tank_3d(long particle_count) {
  StillTank3D t;
  auto& s = t.settings;
  // A 2 x 1 x 1 m column of water (width 2: particles spread over a wider tank).
  const double volume = 2.0 * 1.0 * 1.0;
  const double dp = std::cbrt(volume / static_cast<double>(particle_count));
  s.particle_spacing = dp;
  s.smoothing_length_ratio = 1.3;
  s.kernel = KernelType::wendland_c2;
  s.rest_density = 1000.0;
  s.dynamic_viscosity = 1e-3;
  s.gravity = {0.0, 0.0, -9.81};
  s.sound_speed = 20.0 * std::sqrt(9.81 * 1.0);
  s.density_diffusion = 0.1;
  s.artificial_viscosity = 0.02;
  const double margin = 4.0 * s.support_radius();
  s.domain_lower = {-margin, -margin, -margin};
  s.domain_upper = {2.0 + margin, 1.0 + margin, 1.5 + margin};
  t.scene.walls.push_back(container_box<3>({0.0, 0.0, 0.0}, {2.0, 1.0, 1e9}));
  t.scene.fluid.push_back({{0.0, 0.0, 0.0}, {2.0, 1.0, 1.0}, {}, {}});
  return t;
}

}  // namespace valvefsi::fluid
