#pragma once
// Small helpers shared by the fluid_sph tests.
#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "valvefsi/fluid/fluid_solver.hpp"

namespace valvefsi::fluid::testing {

// Reads a two-column CSV with '#' comment lines and one header line.
inline std::vector<std::pair<double, double>> read_two_column_csv(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::pair<double, double>> rows;
  std::string line;
  bool header_seen = false;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (!header_seen) {
      header_seen = true;
      continue;
    }
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream fields(line);
    double a = 0, b = 0;
    if (fields >> a >> b) rows.emplace_back(a, b);
  }
  return rows;
}

// Largest coordinate along axis among fluid particles (the surge front of a dam break).
template <int D>
double fluid_extent(const FluidSolver<D>& solver, int axis) {
  const auto& p = solver.particles();
  double best = -1e300;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.kind[i] == Kind::fluid) best = std::max(best, p.position[axis][i]);
  return best;
}

// A closed square box of blood (side `box`, from the origin): the settings of the shifting tests
// (density diffusion 0.1, shifting 1, the domain 2 cm beyond the walls).
inline FluidSettings<2> blood_box_settings(double box, double spacing, double sound_speed) {
  FluidSettings<2> s;
  s.particle_spacing = spacing;
  s.rest_density = 1056.0;
  s.dynamic_viscosity = 0.0035;
  s.sound_speed = sound_speed;
  s.density_diffusion = 0.1;
  s.shifting = 1.0;
  s.domain_lower = {-0.02, -0.02};
  s.domain_upper = {box + 0.02, box + 0.02};
  return s;
}

}  // namespace valvefsi::fluid::testing
