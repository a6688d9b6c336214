// Kernels: normalisation (integral of W = 1), the analytic gradient against finite
// differences, and first-order consistency of the discrete gradient on a lattice,
//   sum_b V_b (x_b - x_a) (x) grad_a W_ab = I.
#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "valvefsi/fluid/equation_of_state.hpp"
#include "valvefsi/fluid/kernels.hpp"

namespace valvefsi::fluid {
namespace {

template <class Kernel, int D>
double lattice_sum(const Kernel& W, double dp, double offset, bool gradient, int i_component = 0, int j_component = 0) {
  const int reach = static_cast<int>(std::ceil(2.0 * W.inv_h == 0 ? 0 : 2.0 / (W.inv_h * dp))) + 1;
  double sum = 0;
  const double volume = std::pow(dp, D);
  for (int i = -reach; i <= reach; ++i)
    for (int j = -reach; j <= reach; ++j)
      for (int k = (D == 3 ? -reach : 0); k <= (D == 3 ? reach : 0); ++k) {
        // x_a - x_b for a particle a displaced by `offset` from the lattice.
        const double r[3] = {offset - i * dp, 0.37 * offset - j * dp, D == 3 ? 0.21 * offset - k * dp : 0.0};
        const double dist = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        if (!gradient) {
          sum += volume * W.value(static_cast<float>(dist));
        } else {
          // (x_b - x_a)_i (grad_a W)_j = (-r_i) F r_j
          sum += volume * -r[i_component] * W.gradient_factor(static_cast<float>(dist)) * r[j_component];
        }
      }
  return sum;
}

template <class Kernel, int D>
void check_kernel() {
  const double h = 0.013;
  const Kernel W(h);
  const double dp = h / 1.3;  // the working resolution
  // Normalisation: a fine lattice approximates the integral; h = 1.3 dp is the working case.
  EXPECT_NEAR((lattice_sum<Kernel, D>(W, h / 8, 0.0, false)), 1.0, 2e-4);
  EXPECT_NEAR((lattice_sum<Kernel, D>(W, dp, 0.3 * dp, false)), 1.0, 1e-2);
  // Zero at and beyond the support radius 2h.
  EXPECT_EQ(W.value(static_cast<float>(2.0 * h)), 0.0f);
  EXPECT_EQ(W.gradient_factor(static_cast<float>(2.05 * h)), 0.0f);
  // F = (dW/dr)/r against a central difference.
  for (double q : {0.3, 0.9, 1.1, 1.7}) {
    const double r = q * h, e = 1e-4 * h;
    const double fd = (W.value(static_cast<float>(r + e)) - W.value(static_cast<float>(r - e))) / (2 * e);
    EXPECT_NEAR(W.gradient_factor(static_cast<float>(r)) * r, fd, 2e-3 * std::abs(fd) + 1e-3 * W.value(0.0f) / h)
        << "q = " << q;
  }
  // Gradient consistency: within 3 % at the working h = 1.3 dp, and tighter as the kernel
  // covers more particles (h = 2 dp).
  for (const auto& [ratio, tolerance] : {std::pair{1.3, 3e-2}, std::pair{2.0, 3e-3}})
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j)
        EXPECT_NEAR((lattice_sum<Kernel, D>(W, h / ratio, 0.3 * h / ratio, true, i, j)), i == j ? 1.0 : 0.0, tolerance)
            << "h/dp = " << ratio << ", component " << i << "," << j;
}

TEST(Kernels, CubicSpline2D) { check_kernel<CubicSplineKernel<2>, 2>(); }
TEST(Kernels, CubicSpline3D) { check_kernel<CubicSplineKernel<3>, 3>(); }
TEST(Kernels, WendlandC2_2D) { check_kernel<WendlandC2Kernel<2>, 2>(); }
TEST(Kernels, WendlandC2_3D) { check_kernel<WendlandC2Kernel<3>, 3>(); }

TEST(EquationOfState, LinearMieGruneisenMatchesEq5AndInverts) {
  const LinearMieGruneisen eos{1056.0, 145.0};
  // eq. 5 with s = 0, Gamma0 = 0: p = rho0 c0^2 (1 - rho0/rho).
  const double rho = 1056.0 * 1.001;
  EXPECT_NEAR(eos.pressure(rho - 1056.0), 1056.0 * 145.0 * 145.0 * (1.0 - 1056.0 / rho), 1e-6);
  for (double p : {-5000.0, 0.0, 1333.2, 2.0e6}) EXPECT_NEAR(eos.pressure(eos.density_excess(p)), p, 1e-9 * (1 + std::abs(p)));
}

}  // namespace
}  // namespace valvefsi::fluid
