#include "valvefsi/fluid/interactions.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>

#include "valvefsi/fluid/equation_of_state.hpp"
#include "valvefsi/fluid/kernels.hpp"
#include "valvefsi/fluid/pair_loop.hpp"

namespace valvefsi::fluid {
namespace {

// Settings turned into the float constants the pair loops use.
template <int D>
struct PairConstants {
  float mass, rest_density, h, support2, two_mu, alpha_c0, eta2, diffusion, hydrostatic;
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
        hydrostatic(static_cast<float>(s.rest_density / (s.sound_speed * s.sound_speed))) {
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
constexpr int kBlock = 64;  // lanes per pass; larger cells are processed in several passes

// Masked (cells whose neighbourhood holds a near-surface particle): a per-lane weight of 0
// leaves out the pairs the filter blocks; it is recomputed only for neighbours b where a
// block or b is near the surface, so the SIMD sums themselves are unchanged.
template <int D, bool WithArtificialViscosity, bool WithKernelSum, bool Masked, class Kernel>
[[gnu::noinline]] void cell_block_rates(Particles<D>& particles, const ParticleView<D>& p, const PairConstants<D>& k, const Kernel& W,
                      std::uint32_t first, std::uint32_t last,
                      const std::array<NeighbourSegment<D>, (D == 2 ? 9 : 27)>& segments, int segment_count,
                      const PairFilter<D>& filter) {
  alignas(64) float xa[3][kBlock], va[3][kBlock], wa[3][kBlock], pa[kBlock], inva[kBlock], exa[kBlock];
  alignas(64) float acc[3][kBlock], cont[kBlock], diff[kBlock], csum[kBlock], cg[3][kBlock];
  alignas(64) float keep[kBlock];
  for (std::uint32_t block = first; block < last; block += kBlock) {
    const int n = static_cast<int>(std::min<std::uint32_t>(kBlock, last - block));
    const int padded = (n + kLanes - 1) / kLanes * kLanes;
    bool block_near = false;
    if constexpr (Masked) {
      for (int i = 0; i < kBlock; ++i) keep[i] = 1.0f;
      for (int i = 0; i < n; ++i) block_near = block_near || filter.is_near(block + static_cast<std::uint32_t>(i));
    }
    bool keep_dirty = false;
    for (int i = 0; i < padded; ++i) {
      const bool real = i < n;
      const std::uint32_t a = block + static_cast<std::uint32_t>(real ? i : 0);
      for (int d = 0; d < 3; ++d) {
        const bool axis = d < D;
        xa[d][i] = axis ? (real ? p.x[d][a] : 1e15f) : 0.0f;
        va[d][i] = axis ? p.v[d][a] : 0.0f;
        wa[d][i] = axis ? p.vv[d][a] : 0.0f;
        acc[d][i] = 0.0f;
        cg[d][i] = 0.0f;
      }
      pa[i] = p.pressure[a];
      inva[i] = p.inverse_density[a];
      exa[i] = p.excess[a];
      cont[i] = diff[i] = csum[i] = 0.0f;
    }
    for (int sidx = 0; sidx < segment_count; ++sidx) {
      const auto& seg = segments[sidx];
      float shift[3] = {0, 0, 0};
      for (int d = 0; d < D; ++d) shift[d] = static_cast<float>(seg.shift[d]);
      for (std::uint32_t b = seg.begin; b < seg.end; ++b) {
        const float xb = p.x[0][b] + shift[0], yb = p.x[1][b] + shift[1], zb = D == 3 ? p.x[D - 1][b] + shift[2] : 0.0f;
        const float vxb = p.v[0][b], vyb = p.v[1][b], vzb = D == 3 ? p.v[D - 1][b] : 0.0f;
        const float wxb = p.vv[0][b], wyb = p.vv[1][b], wzb = D == 3 ? p.vv[D - 1][b] : 0.0f;
        const float p_b = p.pressure[b], inv_b = p.inverse_density[b], ex_b = p.excess[b], is_fluid = p.fluid[b];
        if constexpr (Masked) {
          if (block_near || filter.is_near(b)) {
            // Pairs beyond the support have no weight anyway: ask only about the others.
            for (int i = 0; i < n; ++i) {
              const float dx = xa[0][i] - xb, dy = xa[1][i] - yb, dz = D == 3 ? xa[2][i] - zb : 0.0f;
              const bool inside = dx * dx + dy * dy + dz * dz < k.support2;
              keep[i] = inside && filter.blocked(block + static_cast<std::uint32_t>(i), b) ? 0.0f : 1.0f;
            }
            keep_dirty = true;
          } else if (keep_dirty) {
            for (int i = 0; i < n; ++i) keep[i] = 1.0f;
            keep_dirty = false;
          }
        }
#pragma omp simd aligned(xa, va, wa, pa, inva, exa, acc, cont, diff, csum, cg, keep : 64)
        for (int i = 0; i < padded; ++i) {
          const float dx = xa[0][i] - xb, dy = xa[1][i] - yb, dz = D == 3 ? xa[2][i] - zb : 0.0f;
          const float r2 = dx * dx + dy * dy + dz * dz;
          const float r = std::sqrt(r2);
          float F = W.gradient_factor(r);
          if constexpr (Masked) F *= keep[i];
          const float inv_rr = inva[i] * inv_b;
          const float vdx = (va[0][i] - vxb) * dx + (va[1][i] - vyb) * dy + (D == 3 ? (va[2][i] - vzb) * dz : 0.0f);
          cont[i] += vdx * F;
          // Against a wall only the fluid's positive pressure counts: walls push, never pull
          // (a tensile surge tip would otherwise be sucked into the wall it hits).
          const float pa_wall = std::max(pa[i], 0.0f);
          float radial = -(p_b + pa_wall + is_fluid * (pa[i] - pa_wall)) * inv_rr;
          if constexpr (WithArtificialViscosity) {
            const float mu_ab = k.h * std::min(vdx, 0.0f) / (r2 + k.eta2);
            radial += k.alpha_c0 * mu_ab * 0.5f * (inva[i] + inv_b);
          }
          radial *= F;
          const float viscous = k.two_mu * inv_rr * F;
          acc[0][i] += radial * dx + viscous * (wa[0][i] - wxb);
          acc[1][i] += radial * dy + viscous * (wa[1][i] - wyb);
          if constexpr (D == 3) acc[2][i] += radial * dz + viscous * (wa[2][i] - wzb);
          float g_dot_rba = -(k.gravity[0] * dx + k.gravity[1] * dy);
          if constexpr (D == 3) g_dot_rba -= k.gravity[D - 1] * dz;
          diff[i] += is_fluid * (ex_b - exa[i] - k.hydrostatic * g_dot_rba) * (-F) * inv_b;
          if constexpr (WithKernelSum) {
            csum[i] += W.value(r) * (Masked ? keep[i] : 1.0f) * inv_b;
            cg[0][i] += F * dx * inv_b;
            cg[1][i] += F * dy * inv_b;
            if constexpr (D == 3) cg[2][i] += F * dz * inv_b;
          }
        }
      }
    }
    for (int i = 0; i < n; ++i) {
      const std::uint32_t a = block + static_cast<std::uint32_t>(i);
      if (particles.kind[a] != Kind::fluid) continue;
      for (int d = 0; d < D; ++d) particles.acceleration[d][a] = k.mass * acc[d][i] + k.gravity[d];
      particles.density_rate[a] = k.mass * (cont[i] + k.diffusion * diff[i]);
      if constexpr (WithKernelSum) {
        particles.kernel_sum[a] = k.mass * csum[i];
        for (int d = 0; d < D; ++d) particles.kernel_sum_gradient[d][a] = k.mass * cg[d][i];
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
  const float rho0 = static_cast<float>(s.rest_density);
  with_kernel<D>(s.kernel, s.smoothing_length(), [&](const auto& W) {
    for_each_particle_with_neighbours<D>(grid, [&](std::uint32_t w, const auto& segments, int count) {
      if (p.kind[w] != Kind::wall && p.kind[w] != Kind::mirror_wall) return;
      float sum_w = 0, sum_p = 0;
      float sum_rho_r[3] = {0, 0, 0}, sum_v[3] = {0, 0, 0};
      for (int sidx = 0; sidx < count; ++sidx) {
        const auto& seg = segments[sidx];
        float xw[3] = {0, 0, 0};
        for (int d = 0; d < D; ++d) xw[d] = view.x[d][w] - static_cast<float>(seg.shift[d]);
        for (std::uint32_t b = seg.begin; b < seg.end; ++b) {
          if (!acts_as_fluid(view.kind[b])) continue;
          if (filter.active() && filter.blocked(w, b)) continue;
          float dx[3] = {0, 0, 0};
          float r2 = 0;
          for (int d = 0; d < D; ++d) {
            dx[d] = xw[d] - view.x[d][b];
            r2 += dx[d] * dx[d];
          }
          const float wk = W.value(std::sqrt(r2));
          if (wk <= 0.0f) continue;
          const float rho_b = rho0 + view.excess[b];
          sum_w += wk;
          sum_p += view.pressure[b] * wk;
          for (int d = 0; d < D; ++d) {
            sum_rho_r[d] += rho_b * dx[d] * wk;
            sum_v[d] += view.v[d][b] * wk;
          }
        }
      }
      // Adami et al. 2012, eq. 27: p_w = (sum p_f W + (g - a_w) . sum rho_f r_wf W) / sum W;
      // no-slip by the extrapolated velocity, v_w^visc = 2 v_w - v~ (their eq. 22-23).
      const auto& a_w = body_acceleration[p.body[w]];
      p.near_fluid[w] = sum_w > 0.0f;
      if (sum_w > 0.0f) {
        double pw = sum_p;
        for (int d = 0; d < D; ++d) pw += (s.gravity[d] - a_w[d]) * sum_rho_r[d];
        // A wall pushes but never pulls: absolute pressure (with the background) below zero
        // would suck fluid into the wall where a free surface runs along it.
        pw = std::max(pw / sum_w, 0.0);
        p.pressure[w] = static_cast<float>(pw);
        const double excess = eos.density_excess(pw - s.background_pressure);
        p.density_excess[w] = static_cast<float>(excess);
        p.inverse_density[w] = static_cast<float>(1.0 / (s.rest_density + excess));
        for (int d = 0; d < D; ++d) p.viscous_velocity[d][w] = 2.0f * p.velocity[d][w] - sum_v[d] / sum_w;
      } else {
        p.pressure[w] = static_cast<float>(s.background_pressure);
        p.density_excess[w] = 0.0f;
        p.inverse_density[w] = 1.0f / rho0;
        for (int d = 0; d < D; ++d) p.viscous_velocity[d][w] = p.velocity[d][w];
      }
    });
  });
}

template <int D>
void compute_fluid_rates(Particles<D>& p, const CellGrid<D>& grid, const FluidSettings<D>& s, const PairFilter<D>& filter) {
  const PairConstants<D> k(s);
  const ParticleView<D> view(p);
  const bool shifting = s.shifting > 0;
  if (shifting) {
    p.kernel_sum.resize(p.size());
    for (int d = 0; d < D; ++d) p.kernel_sum_gradient[d].resize(p.size());
  }
  const auto cells = static_cast<std::ptrdiff_t>(grid.cell_count());
  with_kernel<D>(s.kernel, s.smoothing_length(), [&](const auto& W) {
#pragma omp parallel
    {
      std::array<NeighbourSegment<D>, (D == 2 ? 9 : 27)> segments;
#pragma omp for schedule(dynamic, 16)
      for (std::ptrdiff_t c = 0; c < cells; ++c) {
        const std::uint32_t first = grid.cell_start(static_cast<std::size_t>(c));
        const std::uint32_t last = grid.cell_start(static_cast<std::size_t>(c) + 1);
        if (first == last) continue;
        bool any_fluid = false;
        for (std::uint32_t a = first; a < last && !any_fluid; ++a) any_fluid = p.kind[a] == Kind::fluid;
        if (!any_fluid) continue;
        const int count = grid.neighbour_segments(static_cast<std::size_t>(c), segments);
        const bool masked = filter.touches(segments, count);
        auto run = [&]<bool AV, bool KS>() {
          if (masked) cell_block_rates<D, AV, KS, true>(p, view, k, W, first, last, segments, count, filter);
          else cell_block_rates<D, AV, KS, false>(p, view, k, W, first, last, segments, count, filter);
        };
        if (k.alpha_c0 > 0) {
          if (shifting) run.template operator()<true, true>();
          else run.template operator()<true, false>();
        } else {
          if (shifting) run.template operator()<false, true>();
          else run.template operator()<false, false>();
        }
      }
    }
  });
}

template <int D>
std::vector<Vec<D>> compute_body_forces(const Particles<D>& p, const CellGrid<D>& grid, const FluidSettings<D>& s,
                                        std::size_t body_count, bool include_fixed_walls, const PairFilter<D>& filter) {
  const PairConstants<D> k(s);
  const ParticleView<D> view(p);
  const int threads = omp_get_max_threads();
  std::vector<double> per_thread(static_cast<std::size_t>(threads) * body_count * D, 0.0);
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
      double* f = per_thread.data() + (static_cast<std::size_t>(omp_get_thread_num()) * body_count + p.body[w]) * D;
      for (int d = 0; d < D; ++d) f[d] += static_cast<double>(k.mass) * k.mass * r.acc[d];
    });
  });
  std::vector<Vec<D>> forces(body_count, Vec<D>{});
  for (int t = 0; t < threads; ++t)
    for (std::size_t b = 0; b < body_count; ++b)
      for (int d = 0; d < D; ++d) forces[b][d] += per_thread[(static_cast<std::size_t>(t) * body_count + b) * D + d];
  return forces;
}

template void update_fluid_pressure<2>(Particles<2>&, const FluidSettings<2>&);
template void update_fluid_pressure<3>(Particles<3>&, const FluidSettings<3>&);
template void update_wall_state<2>(Particles<2>&, const CellGrid<2>&, const FluidSettings<2>&, const std::vector<Vec<2>>&, const PairFilter<2>&);
template void update_wall_state<3>(Particles<3>&, const CellGrid<3>&, const FluidSettings<3>&, const std::vector<Vec<3>>&, const PairFilter<3>&);
template void compute_fluid_rates<2>(Particles<2>&, const CellGrid<2>&, const FluidSettings<2>&, const PairFilter<2>&);
template void compute_fluid_rates<3>(Particles<3>&, const CellGrid<3>&, const FluidSettings<3>&, const PairFilter<3>&);
template std::vector<Vec<2>> compute_body_forces<2>(const Particles<2>&, const CellGrid<2>&, const FluidSettings<2>&, std::size_t, bool, const PairFilter<2>&);
template std::vector<Vec<3>> compute_body_forces<3>(const Particles<3>&, const CellGrid<3>&, const FluidSettings<3>&, std::size_t, bool, const PairFilter<3>&);

}  // namespace valvefsi::fluid
