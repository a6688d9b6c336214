// Start-up of plane Poiseuille flow between plates y = 0 and y = L, periodic along x, driven
// by a body force F from rest (Morris, Fox & Zhu 1997, J. Comput. Phys. 136, 214, eq. 21):
//   u(y, t) = F/(2 nu) y (L - y)
//           - sum_n 4 F L^2 / (nu pi^3 (2n+1)^3) sin(pi y (2n+1)/L) exp(-(2n+1)^2 pi^2 nu t / L^2)
// The error against this series must fall as the resolution rises.
#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "valvefsi/fluid/fluid_solver.hpp"
#include "valvefsi/fluid/geometry.hpp"

namespace valvefsi::fluid {
namespace {

constexpr double L = 1e-3, nu = 1e-6, rho = 1000.0, F = 2e-4;

double analytic_velocity(double y, double t) {
  double u = F / (2 * nu) * y * (L - y);
  for (int n = 0; n < 200; ++n) {
    const double k = 2 * n + 1;
    u -= 4 * F * L * L / (nu * std::pow(std::numbers::pi, 3) * k * k * k) * std::sin(std::numbers::pi * y * k / L) *
         std::exp(-k * k * std::numbers::pi * std::numbers::pi * nu * t / (L * L));
  }
  return u;
}

// Relative L2 error of u_x over all fluid particles at each of the sample times.
std::vector<double> poiseuille_errors(int cells_across, KernelType kernel, const std::vector<double>& times,
                                      double smoothing_length_ratio = 1.3) {
  FluidSettings<2> s;
  s.particle_spacing = L / cells_across;
  s.kernel = kernel;
  s.smoothing_length_ratio = smoothing_length_ratio;
  s.rest_density = rho;
  s.dynamic_viscosity = rho * nu;
  s.gravity = {F, 0.0};            // the driving body force
  s.density_diffusion = 0.0;       // pressure stays uniform; nothing to smooth
  s.sound_speed = 500 * F * L * L / (8 * nu);  // Mach 0.002 at the steady centreline speed
  // The periodic length must hold three kernel supports.
  const double length = std::max(L, s.particle_spacing * std::ceil(3.0 * s.support_radius() / s.particle_spacing));
  s.domain_lower = {0.0, -0.5 * L};
  s.domain_upper = {length, 1.5 * L};
  s.periodic = {true, false};
  SceneGeometry<2> scene;
  scene.walls.push_back(half_space<2>({0.0, 0.0}, {0.0, 1.0}));
  scene.walls.push_back(half_space<2>({0.0, L}, {0.0, -1.0}));
  scene.fluid.push_back({{0.0, 0.0}, {length, L}, {}, [](const Vec<2>&) { return 0.0; }});
  FluidSolver<2> solver(s, fill_particles(scene, s));

  std::vector<double> errors;
  for (double t : times) {
    solver.advance_to(t);
    double num = 0, den = 0;
    const auto& p = solver.particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.kind[i] != Kind::fluid) continue;
      const double exact = analytic_velocity(p.position[1][i], t);
      num += std::pow(p.velocity[0][i] - exact, 2) + std::pow(p.velocity[1][i], 2);
      den += exact * exact;
    }
    errors.push_back(std::sqrt(num / den));
    spdlog::info("Poiseuille L/dp = {}: t = {} s, relative L2 error {:.4f}", cells_across, t, errors.back());
  }
  EXPECT_EQ(solver.lost_count(), 0u);
  return errors;
}

TEST(Poiseuille, TransientErrorFallsWithResolution) {
  const std::vector<double> times = {0.05, 0.2, 1.0};
  const auto coarse = poiseuille_errors(10, KernelType::cubic_spline, times);
  const auto fine = poiseuille_errors(20, KernelType::cubic_spline, times);
  for (std::size_t k = 0; k < times.size(); ++k) {
    EXPECT_LT(fine[k], coarse[k]) << "t = " << times[k];
    EXPECT_LT(fine[k], 0.03) << "t = " << times[k];
  }
}

TEST(Poiseuille, WendlandErrorFallsWithResolution) {
  const auto coarse = poiseuille_errors(10, KernelType::wendland_c2, {1.0}, 2.0);
  const auto fine = poiseuille_errors(20, KernelType::wendland_c2, {1.0}, 2.0);
  const auto finer = poiseuille_errors(40, KernelType::wendland_c2, {1.0}, 2.0);
  EXPECT_LT(fine[0], coarse[0]);
  EXPECT_LT(finer[0], fine[0]);
  EXPECT_LT(finer[0], 0.02);
}

}  // namespace
}  // namespace valvefsi::fluid
