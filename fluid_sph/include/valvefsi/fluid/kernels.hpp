#pragma once
// SPH smoothing kernels W(r, h) with support radius 2h, in 2D and 3D.
// Each kernel gives W and F = (dW/dr) / r, so that grad_a W_ab = F * (r_a - r_b): the
// form the pair loops use, finite at r = 0 and free of a division by r.
#include <algorithm>
#include <cmath>
#include <numbers>

namespace valvefsi::fluid {

enum class KernelType { cubic_spline, wendland_c2 };

// Cubic B-spline of Monaghan & Lattanzio (1985), the reference's kernel (its eq. 1 context).
template <int D>
struct CubicSplineKernel {
  static_assert(D == 2 || D == 3);
  float inv_h;
  float value_scale;     // sigma_D / h^D
  float gradient_scale;  // sigma_D / h^(D+2)

  explicit CubicSplineKernel(double h)
      : inv_h(static_cast<float>(1.0 / h)),
        value_scale(static_cast<float>(sigma() / std::pow(h, D))),
        gradient_scale(static_cast<float>(sigma() / std::pow(h, D + 2))) {}

  static constexpr double sigma() { return D == 2 ? 10.0 / (7.0 * std::numbers::pi) : 1.0 / std::numbers::pi; }
  static constexpr double support_over_h() { return 2.0; }

  float value(float r) const {
    const float q = r * inv_h;
    const float two_minus_q = std::max(2.0f - q, 0.0f);
    const float outer = 0.25f * two_minus_q * two_minus_q * two_minus_q;
    const float inner = 1.0f - 1.5f * q * q + 0.75f * q * q * q;
    return value_scale * (q < 1.0f ? inner : outer);
  }
  // (dW/dr)/r; q > 0 branch divides by q only where q >= 1.
  float gradient_factor(float r) const {
    const float q = r * inv_h;
    const float two_minus_q = std::max(2.0f - q, 0.0f);
    const float outer = -0.75f * two_minus_q * two_minus_q / std::max(q, 1.0f);
    const float inner = -3.0f + 2.25f * q;
    return gradient_scale * (q < 1.0f ? inner : outer);
  }
};

// Wendland C2 (Wendland 1995; normalisation as in Dehnen & Aly 2012 with support 2h).
template <int D>
struct WendlandC2Kernel {
  static_assert(D == 2 || D == 3);
  float inv_h;
  float value_scale;
  float gradient_scale;

  explicit WendlandC2Kernel(double h)
      : inv_h(static_cast<float>(1.0 / h)),
        value_scale(static_cast<float>(alpha() / std::pow(h, D))),
        gradient_scale(static_cast<float>(alpha() / std::pow(h, D + 2))) {}

  static constexpr double alpha() { return D == 2 ? 7.0 / (4.0 * std::numbers::pi) : 21.0 / (16.0 * std::numbers::pi); }
  static constexpr double support_over_h() { return 2.0; }

  float value(float r) const {
    const float q = r * inv_h;
    const float s = std::max(1.0f - 0.5f * q, 0.0f);  // branch-free, so pair loops vectorise
    const float s2 = s * s;
    return value_scale * s2 * s2 * (2.0f * q + 1.0f);
  }
  float gradient_factor(float r) const {
    const float q = r * inv_h;
    const float s = std::max(1.0f - 0.5f * q, 0.0f);
    return gradient_scale * -5.0f * s * s * s;
  }
};

// Calls f(kernel) with the concrete kernel type, so pair loops are compiled once per kernel.
template <int D, class F>
decltype(auto) with_kernel(KernelType type, double h, F&& f) {
  if (type == KernelType::cubic_spline) return f(CubicSplineKernel<D>(h));
  return f(WendlandC2Kernel<D>(h));
}

}  // namespace valvefsi::fluid
