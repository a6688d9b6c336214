// Peak resident memory per particle of the 3D fluid solver (issue 5: at most 300 bytes per
// particle at 1M particles). Builds the still 3D tank of standard_scenes with about N fluid
// particles (default 1,000,000), takes a few steps, and prints the peak resident set
// (getrusage) over the particle count, fluid and walls together, and over the fluid alone.
//   fluid_memory_per_particle [--fluid-particles N] [--steps K]
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <chrono>

#include "valvefsi/fluid/standard_scenes.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Peak resident memory per particle of the 3D fluid solver (still tank)"};
  long fluid_particles = 1'000'000;
  int steps = 3;
  app.add_option("--fluid-particles", fluid_particles, "fluid particles in the tank (about)")->check(CLI::PositiveNumber);
  app.add_option("--steps", steps, "steps to take after the set-up")->check(CLI::NonNegativeNumber);
  CLI11_PARSE(app, argc, argv);

  using namespace valvefsi::fluid;
  const auto start = std::chrono::steady_clock::now();
  auto tank = still_tank_3d(fluid_particles);
  FluidSolver<3> solver(tank.settings, fill_particles(tank.scene, tank.settings));
  for (int k = 0; k < steps; ++k) solver.step();
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const double peak_bytes = static_cast<double>(usage.ru_maxrss) * 1024.0;  // ru_maxrss is in KiB on Linux
  const auto& p = solver.particles();
  const double all = static_cast<double>(p.size());
  const double fluid = static_cast<double>(p.count(Kind::fluid));
  fmt::print("particles {:.0f} ({:.0f} fluid + {:.0f} wall), {} steps, {:.1f} s wall\n", all, fluid, all - fluid, steps, wall_s);
  fmt::print("peak resident set {:.1f} MB: {:.0f} bytes per particle, {:.0f} per fluid particle (target <= 300)\n",
             peak_bytes / 1e6, peak_bytes / all, peak_bytes / fluid);
  return 0;
}
