#include "valvefsi/fluid/interactions.hpp"

#include <omp.h>
#include <xsimd/xsimd.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "valvefsi/fluid/equation_of_state.hpp"
#include "valvefsi/fluid/kernels.hpp"
#include "valvefsi/fluid/pair_loop.hpp"

namespace valvefsi::fluid {
namespace {

// Settings turned into the float constants the pair loops use.
template <int D>
struct PairConstants {
  float mass, rest_density, h, support2, two_mu, alpha_c0, eta2, diffusion, hydrostatic;
  // A squared distance beyond which q = r/h rounds to at least 2 for certain (the support's
  // 2h with a 1e-4 margin, far above the ~1e-7 rounding of sqrt and r/h): every pair term
  // of both kernels is then an exact zero.
  float surely_outside2;
  std::array<float, D> gravity;
  explicit PairConstants(const FluidSettings<D>& s)
      : mass(static_cast<float>(s.particle_mass())),
        rest_density(static_cast<float>(s.rest_density)),
        h(static_cast<float>(s.smoothing_length())),
        support2(static_cast<float>(s.support_radius() * s.support_radius())),
        two_mu(static_cast<float>(2.0 * s.dynamic_viscosity)),
        alpha_c0(static_cast<float>(s.artificial_viscosity * s.sound_speed)),
        eta2(static_cast<float>(0.01 * s.smoothing_length() * s.smoothing_length())),
        diffusion(static_cast<float>(2.0 * s.density_diffusion * s.smoothing_length() * s.sound_speed)),
        hydrostatic(static_cast<float>(s.rest_density / (s.sound_speed * s.sound_speed))),
        surely_outside2(static_cast<float>(s.support_radius() * s.support_radius() * (1.0 + 1e-4))) {
    for (int d = 0; d < D; ++d) gravity[d] = static_cast<float>(s.gravity[d]);
  }
};

// Raw views of the particle arrays, so the inner loops see plain restrict-free pointers.
template <int D>
struct ParticleView {
  std::array<const float*, D> x;
  std::array<const float*, D> v, vv;
  const float* fluid;
  const float* excess;
  const float* inverse_density;
  const float* pressure;
  const Kind* kind;
  explicit ParticleView(const Particles<D>& p) : excess(p.density_excess.data()), inverse_density(p.inverse_density.data()), pressure(p.pressure.data()), kind(p.kind.data()) {
    fluid = p.fluid_mask.data();
    for (int d = 0; d < D; ++d) {
      x[d] = p.local_position[d].data();
      v[d] = p.velocity[d].data();
      vv[d] = p.viscous_velocity[d].data();
    }
  }
};

struct Rates3 {
  float acc[3] = {0.0f, 0.0f, 0.0f};
  float kernel_sum_gradient[3] = {0.0f, 0.0f, 0.0f};  // times 1/m
  float kernel_sum = 0.0f;                            // times 1/m
  float continuity = 0.0f;
  float diffusion = 0.0f;
};

// Sums over the neighbour segments of particle a:
//   continuity:  sum_b (v_a - v_b) . grad_a W_ab                      (eq. 2, times m)
//   momentum:    sum_b [-(p_a + p_b)/(rho_a rho_b) grad_a W_ab          (eq. 3, pressure)
//                       + (mu_a + mu_b)/(rho_a rho_b) r.grad W / r^2 v_ab (eq. 3, viscosity)
//                       - Pi_ab grad_a W_ab]                            (artificial viscosity)
//   diffusion:   sum_b 2 (rho_b - rho_a - rho_ba^H) r_ba.grad_a W / r^2 / rho_b over fluid b
//                (Molteni & Colagrossi 2009 with the hydrostatic part rho0 g.r_ba / c0^2
//                removed, as Fourtakas et al. 2019 do, so a resting column stays at rest).
// OnlyFluidNeighbours restricts the sum to fluid b (used for the force on walls).
// The artificial viscosity uses 1/rho_bar = (1/rho_a + 1/rho_b)/2 instead of
// 2/(rho_a + rho_b): equal to second order in the (sub-percent) density variation, and it
// keeps divisions out of the loop.
// Masked: pairs the filter blocks are left out (scalar calls; only near an immersed surface).
template <int D, bool WithArtificialViscosity, bool OnlyFluidNeighbours, bool WithKernelSum, bool Masked, class Kernel>
inline Rates3 pair_sums(const ParticleView<D>& p, const PairConstants<D>& k, const Kernel& W, std::uint32_t a,
                        const std::array<NeighbourSegment<D>, (D == 2 ? 9 : 27)>& segments, int segment_count,
                        const PairFilter<D>& filter) {
  const float excess_a = p.excess[a];
  const float inv_a = p.inverse_density[a];
  const float p_a = p.pressure[a];
  float va[3] = {0, 0, 0}, vva[3] = {0, 0, 0};
  for (int d = 0; d < D; ++d) {
    va[d] = p.v[d][a];
    vva[d] = p.vv[d][a];
  }
  float ax = 0, ay = 0, az = 0, cont = 0, diff = 0, csum = 0, cgx = 0, cgy = 0, cgz = 0;
  for (int s = 0; s < segment_count; ++s) {
    const auto& seg = segments[s];
    float xa[3] = {0, 0, 0};
    for (int d = 0; d < D; ++d) xa[d] = p.x[d][a] - static_cast<float>(seg.shift[d]);
    const float* x0 = p.x[0];
    const float* x1 = p.x[1];
    const float* x2 = p.x[D - 1];
    const float* v0 = p.v[0];
    const float* v1 = p.v[1];
    const float* v2 = p.v[D - 1];
    const float* w0 = p.vv[0];
    const float* w1 = p.vv[1];
    const float* w2 = p.vv[D - 1];
    const float* ex = p.excess;
    const float* inv = p.inverse_density;
    const float* pr = p.pressure;
    const float* fluid = p.fluid;
#pragma omp simd reduction(+ : ax, ay, az, cont, diff, csum, cgx, cgy, cgz)
    for (std::uint32_t b = seg.begin; b < seg.end; ++b) {
      const float dx = xa[0] - x0[b];
      const float dy = xa[1] - x1[b];
      const float dz = D == 3 ? xa[2] - x2[b] : 0.0f;
      const float r2 = dx * dx + dy * dy + dz * dz;
      const float r = std::sqrt(r2);
      float keep = 1.0f;
      if constexpr (Masked) keep = filter.blocked(a, b) ? 0.0f : 1.0f;
      const float F = W.gradient_factor(r) * keep;  // zero beyond the support
      const float is_fluid = fluid[b];
      const float weight = OnlyFluidNeighbours ? F * is_fluid : F;
      const float inv_b = inv[b];
      const float inv_rr = inv_a * inv_b;
      const float dvx = va[0] - v0[b], dvy = va[1] - v1[b], dvz = D == 3 ? va[2] - v2[b] : 0.0f;
      const float vdx = dvx * dx + dvy * dy + dvz * dz;
      cont += vdx * weight;
      // As in cell_block_rates: a wall feels only the fluid's positive pressure.
      float radial = -(p_a + (OnlyFluidNeighbours ? std::max(pr[b], 0.0f) : pr[b])) * inv_rr;
      if constexpr (WithArtificialViscosity) {
        const float mu_ab = k.h * std::min(vdx, 0.0f) / (r2 + k.eta2);
        radial += k.alpha_c0 * mu_ab * 0.5f * (inv_a + inv_b);
      }
      radial *= weight;
      const float viscous = k.two_mu * inv_rr * weight;
      ax += radial * dx + viscous * (vva[0] - w0[b]);
      ay += radial * dy + viscous * (vva[1] - w1[b]);
      if constexpr (D == 3) az += radial * dz + viscous * (vva[2] - w2[b]);
      float g_dot_rba = -(k.gravity[0] * dx + k.gravity[1] * dy);
      if constexpr (D == 3) g_dot_rba -= k.gravity[D - 1] * dz;
      diff += is_fluid * (ex[b] - excess_a - k.hydrostatic * g_dot_rba) * (-F) * inv_b;
      if constexpr (WithKernelSum) {
        csum += W.value(r) * keep * inv_b;
        cgx += F * dx * inv_b;
        cgy += F * dy * inv_b;
        if constexpr (D == 3) cgz += F * dz * inv_b;
      }
    }
  }
  Rates3 r;
  r.acc[0] = ax;
  r.acc[1] = ay;
  r.acc[2] = az;
  r.continuity = cont;
  r.diffusion = diff;
  r.kernel_sum = csum;
  r.kernel_sum_gradient[0] = cgx;
  r.kernel_sum_gradient[1] = cgy;
  r.kernel_sum_gradient[2] = cgz;
  return r;
}

// The same sums as pair_sums for all particles of one cell at once: the cell's particles are
// the SIMD lanes (padded to a multiple of kLanes with far-away dummies whose kernel weight is
// zero) and each neighbour b is broadcast, so the sums stay in per-lane accumulators with no
// horizontal reduction and no remainder loop. Only lanes that are fluid are written back.
constexpr int kLanes = 8;
constexpr int kBlock = 16;  // lanes per block (for_each_lane_block)
constexpr int kMaxBookedBodies = 8;  // more bodies: the separate compute_body_forces pass

// One block of lanes: the state of its particles and their per-lane sums.
struct alignas(64) LaneBlock {
  alignas(64) float x[3][kBlock], v[3][kBlock], w[3][kBlock], p[kBlock], inv[kBlock], ex[kBlock];
  alignas(64) float acc[3][kBlock], cont[kBlock], diff[kBlock], csum[kBlock], cg[3][kBlock];
  alignas(64) float keep[kBlock];
  alignas(64) float fluid[kBlock];  // 1 where the lane acts as fluid (its reaction is booked)
  alignas(64) float booked[kMaxBookedBodies][3][kBlock];  // pair accelerations from each body's walls
};

// A broadcast neighbour b (position already shifted by its periodic image).
struct Neighbour {
  float x, y, z, vx, vy, vz, wx, wy, wz, p, inv, ex, fluid;
};

// Adds neighbour b's terms to every lane. Book: the pair accelerations are also summed into
// `book` (the lanes' pull from a wall body, whose reaction is the force on that body).
template <int D, bool WithArtificialViscosity, bool WithKernelSum, bool Masked, bool Book, class Kernel>
inline void add_neighbour(LaneBlock& L, const Neighbour& b, int padded, const PairConstants<D>& k, const Kernel& W,
                          float* __restrict book) {
  float* __restrict bx = book;
  float* __restrict by = Book ? book + kBlock : nullptr;
  float* __restrict bz = Book ? book + 2 * kBlock : nullptr;
#pragma omp simd simdlen(8)
  for (int i = 0; i < padded; ++i) {
    const float dx = L.x[0][i] - b.x, dy = L.x[1][i] - b.y, dz = D == 3 ? L.x[2][i] - b.z : 0.0f;
    const float r2 = dx * dx + dy * dy + dz * dz;
    const float r = std::sqrt(r2);
    float F = W.gradient_factor(r);
    if constexpr (Masked) F *= L.keep[i];
    const float inv_rr = L.inv[i] * b.inv;
    const float vdx = (L.v[0][i] - b.vx) * dx + (L.v[1][i] - b.vy) * dy + (D == 3 ? (L.v[2][i] - b.vz) * dz : 0.0f);
    L.cont[i] += vdx * F;
    // Against a wall only the fluid's positive pressure counts: walls push, never pull
    // (a tensile surge tip would otherwise be sucked into the wall it hits).
    const float pa_wall = std::max(L.p[i], 0.0f);
    float radial = -(b.p + pa_wall + b.fluid * (L.p[i] - pa_wall)) * inv_rr;
    if constexpr (WithArtificialViscosity) {
      const float mu_ab = k.h * std::min(vdx, 0.0f) / (r2 + k.eta2);
      radial += k.alpha_c0 * mu_ab * 0.5f * (L.inv[i] + b.inv);
    }
    radial *= F;
    const float viscous = k.two_mu * inv_rr * F;
    const float ax = radial * dx + viscous * (L.w[0][i] - b.wx);
    const float ay = radial * dy + viscous * (L.w[1][i] - b.wy);
    const float az = D == 3 ? radial * dz + viscous * (L.w[2][i] - b.wz) : 0.0f;
    L.acc[0][i] += ax;
    L.acc[1][i] += ay;
    if constexpr (D == 3) L.acc[2][i] += az;
    if constexpr (Book) {
      bx[i] += L.fluid[i] * ax;
      by[i] += L.fluid[i] * ay;
      if constexpr (D == 3) bz[i] += L.fluid[i] * az;
    }
    float g_dot_rba = -(k.gravity[0] * dx + k.gravity[1] * dy);
    if constexpr (D == 3) g_dot_rba -= k.gravity[D - 1] * dz;
    L.diff[i] += b.fluid * (b.ex - L.ex[i] - k.hydrostatic * g_dot_rba) * (-F) * b.inv;
    if constexpr (WithKernelSum) {
      L.csum[i] += W.value(r) * (Masked ? L.keep[i] : 1.0f) * b.inv;
      L.cg[0][i] += F * dx * b.inv;
      L.cg[1][i] += F * dy * b.inv;
      if constexpr (D == 3) L.cg[2][i] += F * dz * b.inv;
    }
  }
}

// The vector of the register passes: 8 floats where AVX2 exists (on Zen 4 a 512-bit op costs
// two 256-bit ones, so 8 lanes lose nothing), else the widest the build targets.
#if XSIMD_WITH_AVX2
using LaneBatch = xsimd::batch<float, xsimd::avx2>;
#else
using LaneBatch = xsimd::batch<float>;
#endif
constexpr int kBatch = static_cast<int>(LaneBatch::size);
static_assert(kBlock % kBatch == 0, "a lane block must be a whole number of vectors");

// The offset from a broadcast neighbour at (bx, by, bz) to the lanes of vector c of x, and its
// squared length: the start of every register sweep's pair term.
struct LaneOffset {
  LaneBatch dx, dy, dz, r2;
};
template <int D, int C>
[[gnu::always_inline]] inline LaneOffset lane_offset(const LaneBatch (&x)[3][C], int c, float bx, float by, float bz) {
  LaneOffset o{x[0][c] - bx, x[1][c] - by, D == 3 ? x[D - 1][c] - bz : LaneBatch(0.0f), LaneBatch(0.0f)};
  o.r2 = o.dx * o.dx + o.dy * o.dy;
  if constexpr (D == 3) o.r2 += o.dz * o.dz;
  return o;
}

// The kernels of kernels.hpp on a vector of distances (same arithmetic as the scalar ones).
template <int D>
inline LaneBatch gradient_factor(const WendlandC2Kernel<D>& W, const LaneBatch& r) {
  const LaneBatch q = r * W.inv_h;
  const LaneBatch s = xsimd::max(LaneBatch(1.0f) - 0.5f * q, LaneBatch(0.0f));
  return (W.gradient_scale * -5.0f) * s * s * s;
}
template <int D>
inline LaneBatch kernel_value(const WendlandC2Kernel<D>& W, const LaneBatch& r) {
  const LaneBatch q = r * W.inv_h;
  const LaneBatch s = xsimd::max(LaneBatch(1.0f) - 0.5f * q, LaneBatch(0.0f));
  const LaneBatch s2 = s * s;
  return W.value_scale * s2 * s2 * (2.0f * q + 1.0f);
}
template <int D>
inline LaneBatch gradient_factor(const CubicSplineKernel<D>& W, const LaneBatch& r) {
  const LaneBatch q = r * W.inv_h;
  const LaneBatch t = xsimd::max(LaneBatch(2.0f) - q, LaneBatch(0.0f));
  const LaneBatch outer = -0.75f * t * t / xsimd::max(q, LaneBatch(1.0f));
  const LaneBatch inner = -3.0f + 2.25f * q;
  return W.gradient_scale * xsimd::select(q < 1.0f, inner, outer);
}
template <int D>
inline LaneBatch kernel_value(const CubicSplineKernel<D>& W, const LaneBatch& r) {
  const LaneBatch q = r * W.inv_h;
  const LaneBatch t = xsimd::max(LaneBatch(2.0f) - q, LaneBatch(0.0f));
  const LaneBatch outer = 0.25f * t * t * t;
  const LaneBatch inner = 1.0f - 1.5f * q * q + 0.75f * q * q * q;
  return W.value_scale * xsimd::select(q < 1.0f, inner, outer);
}

// The neighbours of one block that passed the box test, as broadcast records: the plain ones
// and, per booked body, that body's walls (their pair terms are also summed on their own, as
// the body's reaction). Each list is swept once over all lanes.
// The buffers are sized to the block's candidates before filling (no push_back in the loop).
struct NeighbourLists {
  std::vector<Neighbour> plain;
  std::array<std::vector<Neighbour>, kMaxBookedBodies> booked;
  std::vector<std::uint32_t> kept;  // one segment's candidates that pass the box test
  std::vector<std::uint8_t> near;   // the box test of each of one segment's candidates
  std::size_t plain_count = 0;
  std::array<std::size_t, kMaxBookedBodies> booked_count{};
  void make_room(std::size_t candidates, bool with_bodies) {
    if (plain.size() < candidates) plain.resize(candidates);
    if (with_bodies)
      for (auto& b : booked)
        if (b.size() < candidates) b.resize(candidates);
  }
};

// The same sums as add_neighbour for a whole list of neighbours, with the lanes' state and
// sums held in registers (C vectors of lanes) for the length of the list: no per-pair load and
// store of the per-lane sums. acc: where the list's accelerations are summed (the block's own
// sums, or a body's booking). Viscous: false when mu = 0 (the term is then exactly zero).
// source(take) calls take(neighbour) for every neighbour in order (a list, or the segments).
template <int D, bool WithArtificialViscosity, bool WithKernelSum, bool Viscous, int C, class Kernel, class Source>
[[gnu::always_inline]] inline void sweep_neighbours(LaneBlock& L, Source&& source, float (*acc)[kBlock], const PairConstants<D>& k,
                                                    const Kernel& W) {
  using B = LaneBatch;
  constexpr int S = kBatch;
  B x[3][C], v[3][C], w[3][C], p_wall[C], p_rest[C], inv[C], ex[C];
  B ax[3][C], cont[C], diff[C], csum[C], cg[3][C];
  for (int c = 0; c < C; ++c) {
    const int o = c * S;
    for (int d = 0; d < D; ++d) {
      x[d][c] = B::load_aligned(&L.x[d][o]);
      v[d][c] = B::load_aligned(&L.v[d][o]);
      if constexpr (Viscous) w[d][c] = B::load_aligned(&L.w[d][o]);
      ax[d][c] = B::load_aligned(&acc[d][o]);
      if constexpr (WithKernelSum) cg[d][c] = B::load_aligned(&L.cg[d][o]);
    }
    const B p = B::load_aligned(&L.p[o]);
    // Against a wall only the fluid's positive pressure counts (walls push, never pull).
    p_wall[c] = xsimd::max(p, B(0.0f));
    p_rest[c] = p - p_wall[c];
    inv[c] = B::load_aligned(&L.inv[o]);
    ex[c] = B::load_aligned(&L.ex[o]);
    cont[c] = B::load_aligned(&L.cont[o]);
    diff[c] = B::load_aligned(&L.diff[o]);
    if constexpr (WithKernelSum) csum[c] = B::load_aligned(&L.csum[o]);
  }
  source([&](const Neighbour& b) {
    for (int c = 0; c < C; ++c) {
      const auto [dx, dy, dz, r2] = lane_offset<D>(x, c, b.x, b.y, b.z);
      // A neighbour beyond the support of every lane of this vector adds exact zeros (the
      // sums start at +0 and never become -0, so adding +-0 leaves every bit): skipped.
      if constexpr (C > 1)
        if (xsimd::none(r2 < B(k.surely_outside2))) continue;
      const B r = xsimd::sqrt(r2);
      const B F = gradient_factor(W, r);
      const B inv_rr = inv[c] * b.inv;
      B vdx = (v[0][c] - b.vx) * dx + (v[1][c] - b.vy) * dy;
      if constexpr (D == 3) vdx += (v[D - 1][c] - b.vz) * dz;
      cont[c] += vdx * F;
      B radial = -(b.p + p_wall[c] + b.fluid * p_rest[c]) * inv_rr;
      if constexpr (WithArtificialViscosity) {
        const B mu_ab = k.h * xsimd::min(vdx, B(0.0f)) / (r2 + k.eta2);
        radial += k.alpha_c0 * mu_ab * 0.5f * (inv[c] + b.inv);
      }
      radial *= F;
      if constexpr (Viscous) {
        const B viscous = k.two_mu * inv_rr * F;
        ax[0][c] += radial * dx + viscous * (w[0][c] - b.wx);
        ax[1][c] += radial * dy + viscous * (w[1][c] - b.wy);
        if constexpr (D == 3) ax[D - 1][c] += radial * dz + viscous * (w[D - 1][c] - b.wz);
      } else {
        ax[0][c] += radial * dx;
        ax[1][c] += radial * dy;
        if constexpr (D == 3) ax[D - 1][c] += radial * dz;
      }
      B g_dot_rba = -(k.gravity[0] * dx + k.gravity[1] * dy);
      if constexpr (D == 3) g_dot_rba -= k.gravity[D - 1] * dz;
      diff[c] += b.fluid * (b.ex - ex[c] - k.hydrostatic * g_dot_rba) * (-F) * b.inv;
      if constexpr (WithKernelSum) {
        csum[c] += kernel_value(W, r) * b.inv;
        cg[0][c] += F * dx * b.inv;
        cg[1][c] += F * dy * b.inv;
        if constexpr (D == 3) cg[D - 1][c] += F * dz * b.inv;
      }
    }
  });
  for (int c = 0; c < C; ++c) {
    const int o = c * S;
    for (int d = 0; d < D; ++d) {
      ax[d][c].store_aligned(&acc[d][o]);
      if constexpr (WithKernelSum) cg[d][c].store_aligned(&L.cg[d][o]);
    }
    cont[c].store_aligned(&L.cont[o]);
    diff[c].store_aligned(&L.diff[o]);
    if constexpr (WithKernelSum) csum[c].store_aligned(&L.csum[o]);
  }
}

// sweep_neighbours with C = the number of vectors the block's n lanes fill (1 .. kBlock/kBatch).
template <int D, bool AV, bool KS, bool Viscous, int C = kBlock / kBatch, class Kernel, class Source>
inline void sweep_lanes(int n, LaneBlock& L, const Source& source, float (*acc)[kBlock], const PairConstants<D>& k,
                        const Kernel& W) {
  if constexpr (C > 1) {
    if (n <= (C - 1) * kBatch) return sweep_lanes<D, AV, KS, Viscous, C - 1>(n, L, source, acc, k, W);
  }
  sweep_neighbours<D, AV, KS, Viscous, C>(L, source, acc, k, W);
}

// Bounding box of a block's lanes. A neighbour farther than a support from it meets no lane,
// and the box test is far cheaper than the SIMD pass over the lanes: it drops about half of
// the candidates of the neighbour cells in 3D.
template <int D>
[[gnu::always_inline]] inline void lane_box(const float (&x)[3][kBlock], int n, float* lo, float* hi) {
  for (int d = 0; d < D; ++d) {
    lo[d] = hi[d] = x[d][0];
    for (int i = 1; i < n; ++i) {
      lo[d] = std::min(lo[d], x[d][i]);
      hi[d] = std::max(hi[d], x[d][i]);
    }
  }
}
template <int D>
[[gnu::always_inline]] inline bool near_box(const float* lo, const float* hi, float x, float y, float z, float support2) {
  const float q[3] = {x, y, z};
  float outside2 = 0.0f;
  for (int d = 0; d < D; ++d) {
    const float gap = std::max(std::max(lo[d] - q[d], q[d] - hi[d]), 0.0f);
    outside2 += gap * gap;
  }
  return outside2 < support2;
}

// Which wall bodies' reactions compute_fluid_rates books, and where: per row of cells, summed
// in row order afterwards, so that the bodies' forces (the plates' motion) do not depend on which
// thread took which row (per-thread sums over the dynamic schedule made two runs differ in the
// last bit on a loaded machine).
template <int D>
struct BodyBooking {
  int body_count = 0;          // 0: none
  bool include_fixed = false;  // book body 0 (the fixed walls) too
  double* thread_forces = nullptr;  // body_count * D doubles for the block being booked (its row's)
  bool books(const Particles<D>& p, std::uint32_t b) const {
    return p.kind[b] == Kind::wall && p.body[b] < body_count && (p.body[b] != 0 || include_fixed);
  }
};

// Masked (cells whose neighbourhood holds a near-surface particle): a per-lane weight of 0
// leaves out the pairs the filter blocks; it is recomputed only for neighbours b where a
// block or b is near the surface, so the SIMD sums themselves are unchanged.
// Bodies: the reaction of every fluid-wall pair on the wall's body is booked as it goes
// (Newton's third law: the pair terms are antisymmetric), so the plates and wall loads need
// no pass of their own over the wall particles.
template <int D, bool WithArtificialViscosity, bool WithKernelSum, bool Masked, bool Bodies, class Kernel>
[[gnu::noinline]] void cell_block_rates(Particles<D>& particles, const ParticleView<D>& p, const PairConstants<D>& k, const Kernel& W,
                      const std::uint32_t* lane_index, int n,
                      const std::array<NeighbourSegment<D>, (D == 2 ? 9 : 27)>& segments, int segment_count,
                      const PairFilter<D>& filter, LaneBlock& L, NeighbourLists& lists, const BodyBooking<D>& booking) {
  {
    const int padded = (n + kLanes - 1) / kLanes * kLanes;
    // Lanes loaded: the masked path's vectors of kLanes and the register path's of kBatch.
    constexpr int kLoadMultiple = std::max(kLanes, kBatch);
    const int loaded = (n + kLoadMultiple - 1) / kLoadMultiple * kLoadMultiple;
    bool block_near = false;
    if constexpr (Masked) {
      for (int i = 0; i < kBlock; ++i) L.keep[i] = 1.0f;
      for (int i = 0; i < n; ++i) block_near = block_near || filter.is_near(lane_index[i]);
    }
    bool keep_dirty = false;
    for (int i = 0; i < loaded; ++i) {
      const bool real = i < n;
      const std::uint32_t a = lane_index[real ? i : 0];
      for (int d = 0; d < 3; ++d) {
        const bool axis = d < D;
        L.x[d][i] = axis ? (real ? p.x[d][a] : 1e15f) : 0.0f;
        L.v[d][i] = axis ? p.v[d][a] : 0.0f;
        L.w[d][i] = axis ? p.vv[d][a] : 0.0f;
        L.acc[d][i] = 0.0f;
        L.cg[d][i] = 0.0f;
      }
      L.p[i] = p.pressure[a];
      L.inv[i] = p.inverse_density[a];
      L.ex[i] = p.excess[a];
      L.fluid[i] = real ? p.fluid[a] : 0.0f;
      L.cont[i] = L.diff[i] = L.csum[i] = 0.0f;
    }
    unsigned booked_bodies = 0;  // bit k: body k got a pair this block
    float box_lo[3] = {0, 0, 0}, box_hi[3] = {0, 0, 0};
    lane_box<D>(L.x, n, box_lo, box_hi);
    // Particle b of a segment shifted by `shift` (across periodic sides), as broadcast.
    auto neighbour = [&](std::uint32_t b, const float (&shift)[3]) {
      return Neighbour{p.x[0][b] + shift[0], p.x[1][b] + shift[1], D == 3 ? p.x[D - 1][b] + shift[2] : 0.0f,
                       p.v[0][b], p.v[1][b], D == 3 ? p.v[D - 1][b] : 0.0f,
                       p.vv[0][b], p.vv[1][b], D == 3 ? p.vv[D - 1][b] : 0.0f,
                       p.pressure[b], p.inverse_density[b], p.excess[b], p.fluid[b]};
    };
    // every_candidate(take) calls take(b, nb) for every particle of the segments, in segment
    // order; for_each_candidate only for those within a support of the lanes' box (the others
    // add exact zeros): both paths below see the same neighbours.
    auto every_candidate = [&](auto&& take) {
      for (int sidx = 0; sidx < segment_count; ++sidx) {
        const auto& seg = segments[sidx];
        float shift[3] = {0, 0, 0};
        for (int d = 0; d < D; ++d) shift[d] = static_cast<float>(seg.shift[d]);
        for (std::uint32_t b = seg.begin; b < seg.end; ++b) take(b, neighbour(b, shift));
      }
    };
    auto for_each_candidate = [&](auto&& take) {
      for (int sidx = 0; sidx < segment_count; ++sidx) {
        const auto& seg = segments[sidx];
        float shift[3] = {0, 0, 0};
        for (int d = 0; d < D; ++d) shift[d] = static_cast<float>(seg.shift[d]);
        // The box test keeps about half of the candidates in no predictable pattern: as a
        // branch it mispredicts half the time. So the segment is tested in one vector pass,
        // and the kept indices are compacted without a branch (each index is written, the
        // count grows by the test's 0 or 1).
        const std::uint32_t length = seg.end - seg.begin;
        if (lists.kept.size() < length) {
          lists.kept.resize(length);
          lists.near.resize(length);
        }
        std::uint32_t* kept = lists.kept.data();
        std::uint8_t* near = lists.near.data();
        const float* x0 = p.x[0];
        const float* x1 = p.x[1];
        const float* x2 = p.x[D - 1];
#pragma omp simd
        for (std::uint32_t j = 0; j < length; ++j) {
          const std::uint32_t b = seg.begin + j;
          const float y = x1[b] + shift[1], z = D == 3 ? x2[b] + shift[2] : 0.0f;
          near[j] = near_box<D>(box_lo, box_hi, x0[b] + shift[0], y, z, k.support2) ? 1 : 0;
        }
        std::size_t kept_count = 0;
        for (std::uint32_t j = 0; j < length; ++j) {
          kept[kept_count] = seg.begin + j;
          kept_count += near[j];
        }
        for (std::size_t j = 0; j < kept_count; ++j) take(kept[j], neighbour(kept[j], shift));
      }
    };
    auto sweep = [&](const auto& source, float (*acc)[kBlock]) {
      if (k.two_mu != 0.0f) sweep_lanes<D, WithArtificialViscosity, WithKernelSum, true>(n, L, source, acc, k, W);
      else sweep_lanes<D, WithArtificialViscosity, WithKernelSum, false>(n, L, source, acc, k, W);
    };
    if constexpr (!Masked && !Bodies && D == 2) {
      // 2D without bodies: the box test keeps ~92 % of the candidates, so the segments are
      // swept in place (no test, no list). The neighbours and their order are those of the
      // list path; the candidates it would drop add exact zeros (F = 0 beyond the support).
      sweep([&](auto&& take) { every_candidate([&](std::uint32_t, const Neighbour& nb) { take(nb); }); }, L.acc);
    } else if constexpr (!Masked) {
      // Register path: collect the neighbours that pass the box test, then sweep each list
      // once over all lanes. Per lane the terms are summed in neighbour order, plain ones
      // first, then each booked body's, whatever the block: the sums do not depend on how
      // the lanes were blocked (1 or 2 MPI ranks agree bit for bit).
      std::size_t candidates = 0;
      for (int sidx = 0; sidx < segment_count; ++sidx) candidates += segments[sidx].end - segments[sidx].begin;
      lists.make_room(candidates, Bodies);
      Neighbour* plain = lists.plain.data();
      std::size_t plain_count = 0;
      for_each_candidate([&](std::uint32_t b, const Neighbour& nb) {
        if constexpr (Bodies) {
          if (booking.books(particles, b)) {
            const unsigned body = particles.body[b];
            if (!(booked_bodies & (1u << body))) {
              lists.booked_count[body] = 0;
              booked_bodies |= 1u << body;
            }
            lists.booked[body][lists.booked_count[body]++] = nb;
            return;
          }
        }
        plain[plain_count++] = nb;
      });
      auto list = [](const Neighbour* nb, std::size_t count) {
        return [nb, count](auto&& take) {
          for (std::size_t j = 0; j < count; ++j) take(nb[j]);
        };
      };
      sweep(list(plain, plain_count), L.acc);
      if constexpr (Bodies) {
        for (unsigned body = 0; booked_bodies >> body; ++body) {
          if (!(booked_bodies & (1u << body))) continue;
          for (int d = 0; d < 3; ++d)
            for (int i = 0; i < kBlock; ++i) L.booked[body][d][i] = 0.0f;
          sweep(list(lists.booked[body].data(), lists.booked_count[body]), L.booked[body]);
          for (int d = 0; d < D; ++d)
            for (int i = 0; i < n; ++i) L.acc[d][i] += L.booked[body][d][i];
        }
      }
    } else {
      for_each_candidate([&](std::uint32_t b, const Neighbour& nb) {
        if constexpr (Masked) {
          if (block_near || filter.is_near(b)) {
            // Pairs beyond the support have no weight anyway: ask only about the others.
            for (int i = 0; i < n; ++i) {
              const float dx = L.x[0][i] - nb.x, dy = L.x[1][i] - nb.y, dz = D == 3 ? L.x[2][i] - nb.z : 0.0f;
              const bool inside = dx * dx + dy * dy + dz * dz < k.support2;
              L.keep[i] = inside && filter.blocked(lane_index[i], b) ? 0.0f : 1.0f;
            }
            keep_dirty = true;
          } else if (keep_dirty) {
            for (int i = 0; i < n; ++i) L.keep[i] = 1.0f;
            keep_dirty = false;
          }
        }
        if constexpr (Bodies) {
          if (booking.books(particles, b)) {
            const unsigned body = particles.body[b];
            if (!(booked_bodies & (1u << body))) {
              for (int d = 0; d < 3; ++d)
                for (int i = 0; i < kBlock; ++i) L.booked[body][d][i] = 0.0f;
              booked_bodies |= 1u << body;
            }
            add_neighbour<D, WithArtificialViscosity, WithKernelSum, Masked, true>(L, nb, padded, k, W, &L.booked[body][0][0]);
            return;
          }
        }
        add_neighbour<D, WithArtificialViscosity, WithKernelSum, Masked, false>(L, nb, padded, k, W, nullptr);
      });
    }
    for (int i = 0; i < n; ++i) {
      const std::uint32_t a = lane_index[i];
      if (particles.kind[a] != Kind::fluid) continue;
      for (int d = 0; d < D; ++d) particles.acceleration[d][a] = k.mass * L.acc[d][i] + k.gravity[d];
      particles.density_rate[a] = k.mass * (L.cont[i] + k.diffusion * L.diff[i]);
      if constexpr (WithKernelSum) {
        particles.kernel_sum[a] = k.mass * L.csum[i];
        for (int d = 0; d < D; ++d) particles.kernel_sum_gradient[d][a] = k.mass * L.cg[d][i];
      }
    }
    if constexpr (Bodies) {
      // Force on the body = - m_a m_b (the lanes' pair accelerations from its walls).
      for (unsigned body = 0; booked_bodies >> body; ++body) {
        if (!(booked_bodies & (1u << body))) continue;
        for (int d = 0; d < D; ++d) {
          float sum = 0.0f;
          // (The masked path's bookings are already times the lane's fluid flag, 0 or 1.)
          for (int i = 0; i < n; ++i) sum += L.fluid[i] * L.booked[body][d][i];
          booking.thread_forces[body * D + d] -= static_cast<double>(k.mass) * k.mass * sum;
        }
      }
    }
  }
}

// Per-lane sums of the generalized wall condition for one block of a cell's particles.
struct alignas(64) WallLanes {
  alignas(64) float x[3][kBlock], keep[kBlock];
  alignas(64) float sum_w[kBlock], sum_p[kBlock], sum_rho_r[3][kBlock], sum_v[3][kBlock];
};

// A fluid neighbour of a wall block, as broadcast to the lanes.
struct WallNeighbour {
  float x, y, z, rho, p, vx, vy, vz;
};

// The wall state's sums for a whole list of fluid neighbours, the lanes' sums in registers
// (C vectors of lanes) for the length of the list, as sweep_neighbours does for the rates.
// surely_outside2: as PairConstants' (a vector of lanes all beyond it gets exact zeros).
template <int D, int C, class Kernel>
inline void sweep_wall_neighbours(WallLanes& L, const WallNeighbour* nb, std::size_t count, const Kernel& W, float surely_outside2) {
  using B = LaneBatch;
  constexpr int S = kBatch;
  B x[3][C], sum_w[C], sum_p[C], sum_rho_r[3][C], sum_v[3][C];
  for (int c = 0; c < C; ++c) {
    for (int d = 0; d < D; ++d) {
      x[d][c] = B::load_aligned(&L.x[d][c * S]);
      sum_rho_r[d][c] = sum_v[d][c] = B(0.0f);
    }
    sum_w[c] = sum_p[c] = B(0.0f);
  }
  for (std::size_t j = 0; j < count; ++j) {
    const WallNeighbour& b = nb[j];
    for (int c = 0; c < C; ++c) {
      const auto [dx, dy, dz, r2] = lane_offset<D>(x, c, b.x, b.y, b.z);
      if constexpr (C > 1)
        if (xsimd::none(r2 < B(surely_outside2))) continue;
      const B wk = kernel_value(W, xsimd::sqrt(r2));
      sum_w[c] += wk;
      sum_p[c] += b.p * wk;
      const B rho_w = b.rho * wk;
      sum_rho_r[0][c] += rho_w * dx;
      sum_rho_r[1][c] += rho_w * dy;
      if constexpr (D == 3) sum_rho_r[D - 1][c] += rho_w * dz;
      sum_v[0][c] += b.vx * wk;
      sum_v[1][c] += b.vy * wk;
      if constexpr (D == 3) sum_v[D - 1][c] += b.vz * wk;
    }
  }
  for (int c = 0; c < C; ++c) {
    const int o = c * S;
    sum_w[c].store_aligned(&L.sum_w[o]);
    sum_p[c].store_aligned(&L.sum_p[o]);
    for (int d = 0; d < D; ++d) {
      sum_rho_r[d][c].store_aligned(&L.sum_rho_r[d][o]);
      sum_v[d][c].store_aligned(&L.sum_v[d][o]);
    }
  }
}

template <int D, int C = kBlock / kBatch, class Kernel>
inline void sweep_wall_lanes(int n, WallLanes& L, const WallNeighbour* list, std::size_t count, const Kernel& W,
                             float surely_outside2) {
  if constexpr (C > 1) {
    if (n <= (C - 1) * kBatch) return sweep_wall_lanes<D, C - 1>(n, L, list, count, W, surely_outside2);
  }
  sweep_wall_neighbours<D, C>(L, list, count, W, surely_outside2);
}

// Sums over the fluid neighbours of every wall lane of one cell (SIMD over the lanes, each
// fluid neighbour broadcast, as in cell_block_rates), then sets the lanes' wall state.
template <int D, bool Masked, class Kernel>
[[gnu::noinline]] void cell_block_wall_state(Particles<D>& particles, const ParticleView<D>& p, const FluidSettings<D>& s,
                                             const LinearMieGruneisen& eos, const Kernel& W, const std::uint32_t* lane_index,
                                             int n, const std::array<NeighbourSegment<D>, (D == 2 ? 9 : 27)>& segments,
                                             int segment_count, const PairFilter<D>& filter,
                                             const std::vector<Vec<D>>& body_acceleration, float support2,
                                             float surely_outside2, WallLanes& L,
                                             std::vector<WallNeighbour>& list) {
  const float rho0 = static_cast<float>(s.rest_density);
  {
    constexpr int kLoadMultiple = std::max(kLanes, kBatch);
    const int padded = (n + kLoadMultiple - 1) / kLoadMultiple * kLoadMultiple;
    bool block_near = false;
    if constexpr (Masked) {
      for (int i = 0; i < kBlock; ++i) L.keep[i] = 1.0f;
      for (int i = 0; i < n; ++i) block_near = block_near || filter.is_near(lane_index[i]);
    }
    bool keep_dirty = false;
    bool any_wall = false;  // a lane that is a wall, not an image
    for (int i = 0; i < padded; ++i) {
      const bool real = i < n;
      const std::uint32_t a = lane_index[real ? i : 0];
      for (int d = 0; d < 3; ++d) {
        L.x[d][i] = d < D ? (real ? p.x[d][a] : 1e15f) : 0.0f;
        L.sum_rho_r[d][i] = L.sum_v[d][i] = 0.0f;
      }
      L.sum_w[i] = L.sum_p[i] = 0.0f;
      any_wall = any_wall || (real && p.kind[a] == Kind::wall);
    }
    float box_lo[3] = {0, 0, 0}, box_hi[3] = {0, 0, 0};
    lane_box<D>(L.x, n, box_lo, box_hi);
    std::size_t candidates = 0, listed = 0;
    for (int sidx = 0; sidx < segment_count; ++sidx) candidates += segments[sidx].end - segments[sidx].begin;
    if (list.size() < candidates) list.resize(candidates);
    for (int sidx = 0; sidx < segment_count; ++sidx) {
      const auto& seg = segments[sidx];
      float shift[3] = {0, 0, 0};
      for (int d = 0; d < D; ++d) shift[d] = static_cast<float>(seg.shift[d]);
      for (std::uint32_t b = seg.begin; b < seg.end; ++b) {
        if (p.fluid[b] == 0.0f) continue;  // only fluid (and its mirror images) is extrapolated
        const float xb = p.x[0][b] + shift[0], yb = p.x[1][b] + shift[1], zb = D == 3 ? p.x[D - 1][b] + shift[2] : 0.0f;
        if (!near_box<D>(box_lo, box_hi, xb, yb, zb, support2)) continue;
        // Mirror fluid near a wall takes a lane in the rates pass, to book its push on the wall.
        if (any_wall && p.kind[b] == Kind::mirror_fluid) __atomic_store_n(&particles.near_wall[b], std::uint8_t{1}, __ATOMIC_RELAXED);
        const float rho_b = rho0 + p.excess[b], p_b = p.pressure[b];
        const float vxb = p.v[0][b], vyb = p.v[1][b], vzb = D == 3 ? p.v[D - 1][b] : 0.0f;
        if constexpr (!Masked) {
          list[listed++] = {xb, yb, zb, rho_b, p_b, vxb, vyb, vzb};
          continue;
        }
        if constexpr (Masked) {
          if (block_near || filter.is_near(b)) {
            for (int i = 0; i < n; ++i) {
              const float dx = L.x[0][i] - xb, dy = L.x[1][i] - yb, dz = D == 3 ? L.x[2][i] - zb : 0.0f;
              const bool inside = dx * dx + dy * dy + dz * dz < support2;
              L.keep[i] = inside && filter.blocked(lane_index[i], b) ? 0.0f : 1.0f;
            }
            keep_dirty = true;
          } else if (keep_dirty) {
            for (int i = 0; i < n; ++i) L.keep[i] = 1.0f;
            keep_dirty = false;
          }
        }
#pragma omp simd simdlen(8)
        for (int i = 0; i < padded; ++i) {
          const float dx = L.x[0][i] - xb, dy = L.x[1][i] - yb, dz = D == 3 ? L.x[2][i] - zb : 0.0f;
          float wk = W.value(std::sqrt(dx * dx + dy * dy + dz * dz));
          if constexpr (Masked) wk *= L.keep[i];
          L.sum_w[i] += wk;
          L.sum_p[i] += p_b * wk;
          L.sum_rho_r[0][i] += rho_b * dx * wk;
          L.sum_rho_r[1][i] += rho_b * dy * wk;
          if constexpr (D == 3) L.sum_rho_r[2][i] += rho_b * dz * wk;
          L.sum_v[0][i] += vxb * wk;
          L.sum_v[1][i] += vyb * wk;
          if constexpr (D == 3) L.sum_v[2][i] += vzb * wk;
        }
      }
    }
    if constexpr (!Masked) sweep_wall_lanes<D>(n, L, list.data(), listed, W, surely_outside2);
    for (int i = 0; i < n; ++i) {
      const std::uint32_t w = lane_index[i];
      if (particles.kind[w] != Kind::wall && particles.kind[w] != Kind::mirror_wall) continue;
      // Adami et al. 2012, eq. 27: p_w = (sum p_f W + (g - a_w) . sum rho_f r_wf W) / sum W;
      // no-slip by the extrapolated velocity, v_w^visc = 2 v_w - v~ (their eq. 22-23).
      const auto& a_w = body_acceleration[particles.body[w]];
      const float sum_w = L.sum_w[i];
      particles.near_fluid[w] = sum_w > 0.0f;
      if (sum_w > 0.0f) {
        double pw = L.sum_p[i];
        for (int d = 0; d < D; ++d) pw += (s.gravity[d] - a_w[d]) * L.sum_rho_r[d][i];
        // A wall pushes but never pulls: absolute pressure (with the background) below zero
        // would suck fluid into the wall where a free surface runs along it.
        pw = std::max(pw / sum_w, 0.0);
        particles.pressure[w] = static_cast<float>(pw);
        const double excess = eos.density_excess(pw - s.background_pressure);
        particles.density_excess[w] = static_cast<float>(excess);
        particles.inverse_density[w] = static_cast<float>(1.0 / (s.rest_density + excess));
        for (int d = 0; d < D; ++d) particles.viscous_velocity[d][w] = 2.0f * particles.velocity[d][w] - L.sum_v[d][i] / sum_w;
      } else {
        particles.pressure[w] = static_cast<float>(s.background_pressure);
        particles.density_excess[w] = 0.0f;
        particles.inverse_density[w] = 1.0f / rho0;
        for (int d = 0; d < D; ++d) particles.viscous_velocity[d][w] = particles.velocity[d][w];
      }
    }
  }
}

}  // namespace

template <int D>
void update_fluid_pressure(Particles<D>& p, const FluidSettings<D>& s) {
  const LinearMieGruneisen eos{s.rest_density, s.sound_speed};
  const auto n = static_cast<std::ptrdiff_t>(p.size());
  const float bulk = static_cast<float>(eos.bulk_modulus());
  const float rho0 = static_cast<float>(s.rest_density);
  float* pressure = p.pressure.data();
  const float* excess = p.density_excess.data();
  const Kind* kind = p.kind.data();
  float* inverse = p.inverse_density.data();
  const float background = static_cast<float>(s.background_pressure);
#pragma omp parallel for simd schedule(static)
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    if (kind[i] == Kind::fluid || kind[i] == Kind::mirror_fluid) {
      inverse[i] = 1.0f / (rho0 + excess[i]);
      pressure[i] = bulk * excess[i] * inverse[i] + background;  // eq. 5 with s = 0, Gamma0 = 0
    }
  }
}

template <int D>
void update_wall_state(Particles<D>& p, const CellGrid<D>& grid, const FluidSettings<D>& s,
                       const std::vector<Vec<D>>& body_acceleration, const PairFilter<D>& filter) {
  const LinearMieGruneisen eos{s.rest_density, s.sound_speed};
  const ParticleView<D> view(p);
  const float support2 = static_cast<float>(s.support_radius() * s.support_radius());
  const float surely_outside2 = PairConstants<D>(s).surely_outside2;
  std::fill(p.near_wall.begin(), p.near_wall.end(), std::uint8_t{0});
  with_kernel<D>(s.kernel, s.smoothing_length(), [&](const auto& W) {
#pragma omp parallel
    {
      WallLanes lanes;
      std::vector<WallNeighbour> list;
      for_each_lane_block<D, kBlock>(
          grid, [&](std::uint32_t a) { return p.kind[a] == Kind::wall || p.kind[a] == Kind::mirror_wall; },
          [&](const std::uint32_t* lane_index, int n, const auto& segments, int count, std::ptrdiff_t /*row*/) {
            if (filter.touches(segments, count))
              cell_block_wall_state<D, true>(p, view, s, eos, W, lane_index, n, segments, count, filter, body_acceleration, support2, surely_outside2, lanes, list);
            else
              cell_block_wall_state<D, false>(p, view, s, eos, W, lane_index, n, segments, count, filter, body_acceleration, support2, surely_outside2, lanes, list);
          });
    }
  });
}

template <int D>
void compute_fluid_rates(Particles<D>& p, const CellGrid<D>& grid, const FluidSettings<D>& s, const PairFilter<D>& filter,
                         std::vector<Vec<D>>* body_forces, bool include_fixed_walls, std::size_t lane_begin,
                         std::size_t lane_end) {
  const PairConstants<D> k(s);
  const ParticleView<D> view(p);
  const bool shifting = s.shifting > 0;
  if (shifting) {
    p.kernel_sum.resize(p.size());
    for (int d = 0; d < D; ++d) p.kernel_sum_gradient[d].resize(p.size());
  }
  const int body_count = body_forces != nullptr ? static_cast<int>(body_forces->size()) : 0;
  if (body_count > kMaxBookedBodies) {
    // Too many bodies to book in the pair loop: the separate pass over the wall particles.
    if (lane_begin != 0 || lane_end < p.size())
      throw std::invalid_argument("compute_fluid_rates: more than " + std::to_string(kMaxBookedBodies) +
                                  " bodies are not supported in a run split over MPI ranks");
    compute_fluid_rates<D>(p, grid, s, filter);
    *body_forces = compute_body_forces<D>(p, grid, s, static_cast<std::size_t>(body_count), include_fixed_walls, filter);
    return;
  }
  const std::size_t stride = static_cast<std::size_t>(std::max(body_count, 1)) * D;
  const std::size_t rows = body_count > 0 ? grid.cell_count() / static_cast<std::size_t>(grid.cells_along(0)) : 0;
  std::vector<double> per_row(rows * stride, 0.0);
    with_kernel<D>(s.kernel, s.smoothing_length(), [&](const auto& W) {
#pragma omp parallel
    {
      LaneBlock lanes;
      NeighbourLists lists;
      BodyBooking<D> booking;
      booking.body_count = body_count;
      booking.include_fixed = include_fixed_walls;
      // Rates are needed for the fluid; booked reactions also where mirror fluid meets a wall.
      auto wanted = [&](std::uint32_t a) {
        return a >= lane_begin && a < lane_end &&
               (p.kind[a] == Kind::fluid || (body_count > 0 && p.kind[a] == Kind::mirror_fluid && p.near_wall[a] != 0));
      };
      for_each_lane_block<D, kBlock>(grid, wanted, [&](const std::uint32_t* lane_index, int n, const auto& segments, int count,
                                                       std::ptrdiff_t row) {
        if (body_count > 0) booking.thread_forces = per_row.data() + static_cast<std::size_t>(row) * stride;
        const bool masked = filter.touches(segments, count);
        auto run = [&]<bool AV, bool KS>() {
          if (body_count > 0) {
            if (masked) cell_block_rates<D, AV, KS, true, true>(p, view, k, W, lane_index, n, segments, count, filter, lanes, lists, booking);
            else cell_block_rates<D, AV, KS, false, true>(p, view, k, W, lane_index, n, segments, count, filter, lanes, lists, booking);
          } else {
            if (masked) cell_block_rates<D, AV, KS, true, false>(p, view, k, W, lane_index, n, segments, count, filter, lanes, lists, booking);
            else cell_block_rates<D, AV, KS, false, false>(p, view, k, W, lane_index, n, segments, count, filter, lanes, lists, booking);
          }
        };
        if (k.alpha_c0 > 0) {
          if (shifting) run.template operator()<true, true>();
          else run.template operator()<true, false>();
        } else {
          if (shifting) run.template operator()<false, true>();
          else run.template operator()<false, false>();
        }
      });
    }
  });
  if (body_count == 0) return;
  body_forces->assign(static_cast<std::size_t>(body_count), Vec<D>{});
  for (std::size_t r = 0; r < rows; ++r)
    for (int b = 0; b < body_count; ++b)
      for (int d = 0; d < D; ++d) (*body_forces)[b][d] += per_row[r * stride + static_cast<std::size_t>(b) * D + d];
}

template <int D>
std::vector<Vec<D>> compute_body_forces(const Particles<D>& p, const CellGrid<D>& grid, const FluidSettings<D>& s,
                                        std::size_t body_count, bool include_fixed_walls, const PairFilter<D>& filter) {
  const PairConstants<D> k(s);
  const ParticleView<D> view(p);
  // Booked per chunk of cells (one thread takes a whole chunk) and summed in chunk order, so that
  // the result does not depend on the thread schedule (as compute_fluid_rates books per row).
  const std::size_t chunks = (grid.cell_count() + kCellChunk - 1) / kCellChunk;
  const auto& starts = grid.cell_starts();
  std::vector<double> per_chunk(chunks * body_count * D, 0.0);
  with_kernel<D>(s.kernel, s.smoothing_length(), [&](const auto& W) {
    for_each_particle_with_neighbours<D>(grid, [&](std::uint32_t w, const auto& segments, int count) {
      if (p.kind[w] != Kind::wall || p.body[w] >= body_count || !p.near_fluid[w]) return;
      if (p.body[w] == 0 && !include_fixed_walls) return;
      Rates3 r;
      if (filter.touches(segments, count))
        r = k.alpha_c0 > 0 ? pair_sums<D, true, true, false, true>(view, k, W, w, segments, count, filter)
                           : pair_sums<D, false, true, false, true>(view, k, W, w, segments, count, filter);
      else
        r = k.alpha_c0 > 0 ? pair_sums<D, true, true, false, false>(view, k, W, w, segments, count, filter)
                           : pair_sums<D, false, true, false, false>(view, k, W, w, segments, count, filter);
      // w's cell: the last cell that starts at or before it (one thread takes a whole cell)
      const auto cell = static_cast<std::size_t>(std::upper_bound(starts.begin(), starts.begin() + grid.cell_count() + 1, w) -
                                                 starts.begin() - 1);
      double* f = per_chunk.data() + ((cell / kCellChunk) * body_count + p.body[w]) * D;
      for (int d = 0; d < D; ++d) f[d] += static_cast<double>(k.mass) * k.mass * r.acc[d];
    });
  });
  std::vector<Vec<D>> forces(body_count, Vec<D>{});
  for (std::size_t c = 0; c < chunks; ++c)
    for (std::size_t b = 0; b < body_count; ++b)
      for (int d = 0; d < D; ++d) forces[b][d] += per_chunk[(c * body_count + b) * D + d];
  return forces;
}

template void update_fluid_pressure<2>(Particles<2>&, const FluidSettings<2>&);
template void update_fluid_pressure<3>(Particles<3>&, const FluidSettings<3>&);
template void update_wall_state<2>(Particles<2>&, const CellGrid<2>&, const FluidSettings<2>&, const std::vector<Vec<2>>&, const PairFilter<2>&);
template void update_wall_state<3>(Particles<3>&, const CellGrid<3>&, const FluidSettings<3>&, const std::vector<Vec<3>>&, const PairFilter<3>&);
template void compute_fluid_rates<2>(Particles<2>&, const CellGrid<2>&, const FluidSettings<2>&, const PairFilter<2>&, std::vector<Vec<2>>*, bool, std::size_t, std::size_t);
template void compute_fluid_rates<3>(Particles<3>&, const CellGrid<3>&, const FluidSettings<3>&, const PairFilter<3>&, std::vector<Vec<3>>*, bool, std::size_t, std::size_t);
template std::vector<Vec<2>> compute_body_forces<2>(const Particles<2>&, const CellGrid<2>&, const FluidSettings<2>&, std::size_t, bool, const PairFilter<2>&);
template std::vector<Vec<3>> compute_body_forces<3>(const Particles<3>&, const CellGrid<3>&, const FluidSettings<3>&, std::size_t, bool, const PairFilter<3>&);

}  // namespace valvefsi::fluid
