#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "valvefsi/fluid/interactions.hpp"
#include "valvefsi/fluid/kernels.hpp"
#include "valvefsi/fluid/pair_loop.hpp"

namespace valvefsi::fluid {
namespace {

// Solves A x = b for a symmetric positive D x D matrix; false if A is (nearly) singular.
template <int D>
bool solve_small(const std::array<std::array<double, D>, D>& A, const std::array<double, D>& b, std::array<double, D>& x) {
  if constexpr (D == 2) {
    const double det = A[0][0] * A[1][1] - A[0][1] * A[1][0];
    if (!(std::abs(det) > 1e-6)) return false;
    x[0] = (b[0] * A[1][1] - A[0][1] * b[1]) / det;
    x[1] = (A[0][0] * b[1] - A[1][0] * b[0]) / det;
  } else {
    const double c00 = A[1][1] * A[2][2] - A[1][2] * A[2][1];
    const double c01 = A[1][2] * A[2][0] - A[1][0] * A[2][2];
    const double c02 = A[1][0] * A[2][1] - A[1][1] * A[2][0];
    const double det = A[0][0] * c00 + A[0][1] * c01 + A[0][2] * c02;
    if (!(std::abs(det) > 1e-6)) return false;
    // Cramer's rule, column by column.
    for (int k = 0; k < 3; ++k) {
      auto M = A;
      for (int r = 0; r < 3; ++r) M[r][k] = b[r];
      x[k] = (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
              M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0])) / det;
    }
  }
  return true;
}

}  // namespace

template <int D>
void shifting_density_change(const Particles<D>& p, const CellGrid<D>& grid, const FluidSettings<D>& s, const PairFilter<D>& filter,
                             const std::array<std::vector<double>, D>& shift, std::vector<float>& change, std::size_t begin,
                             std::size_t end) {
  using Mode = typename FluidSettings<D>::ShiftingDensity;
  change.assign(p.size(), 0.0f);
  if (s.shifting_density == Mode::keep) return;
  const bool field = s.shifting_density == Mode::field_gradient;
  const double mass = s.particle_mass(), rho0 = s.rest_density;
  const bool filtered = filter.active();
  const float support2 = static_cast<float>(s.support_radius() * s.support_radius());
  with_kernel<D>(s.kernel, s.smoothing_length(), [&](const auto& W) {
    for_each_particle_with_neighbours<D>(grid, [&](std::uint32_t a, const auto& segments, int count) {
      if (a < begin || a >= end || p.kind[a] != Kind::fluid) return;
      bool moves = false;
      for (int d = 0; d < D; ++d) moves = moves || shift[d][a] != 0.0;
      if (field && !moves) return;  // (continuity: its neighbours' shifts may still compress it)
      // Continuity: not within a support of an immersed surface. There part of the kernel is the
      // surface's (the thin leaflet's virtual layers, not particles here), so the sum is
      // one-sided; on the 2D valve the raw correction there ran the leaflet away during the
      // opening (0.077 s), and completing it with the surface's part of grad C (as if it were a
      // wall that does not move) sooner (0.048 s). smooth_shifting_density_change then gives
      // these particles their neighbours' mean.
      if (!field && filtered && filter.is_near(a)) return;
      const double rho_a = rho0 + p.density_excess[a];
      // field: g = sum_b V_b (rho_b - rho_a) grad W and A = sum_b V_b grad W (x) (x_b - x_a)
      // over the fluid b, so grad rho = A^-1 g is exact for a linear field on any packing.
      // continuity: sum_b (dr_a - dr_b) . grad W over every neighbour, the code's continuity sum.
      std::array<double, D> g{};
      std::array<std::array<double, D>, D> A{};
      double continuity = 0.0;
      for (int k = 0; k < count; ++k) {
        const auto& seg = segments[k];
        for (std::uint32_t b = seg.begin; b < seg.end; ++b) {
          if (b == a || p.kind[b] == Kind::lost) continue;
          if (field && !acts_as_fluid(p.kind[b])) continue;
          // Float offsets as in the pair loops (positions relative to the grid's corner).
          std::array<float, D> dx{};
          float r2 = 0.0f;
          for (int d = 0; d < D; ++d) {
            dx[d] = p.local_position[d][a] - (p.local_position[d][b] + static_cast<float>(seg.shift[d]));
            r2 += dx[d] * dx[d];
          }
          if (r2 >= support2) continue;
          const double F = W.gradient_factor(std::sqrt(r2));
          if (filtered && filter.blocked(a, b)) continue;
          if (field) {
            const double V = mass * p.inverse_density[b];
            const double drho = rho0 + p.density_excess[b] - rho_a;
            for (int i = 0; i < D; ++i) {
              g[i] += V * drho * F * dx[i];
              for (int j = 0; j < D; ++j) A[i][j] -= V * F * dx[i] * dx[j];
            }
          } else {
            for (int d = 0; d < D; ++d) continuity += (shift[d][a] - shift[d][b]) * F * dx[d];
          }
        }
      }
      double drho = 0.0;
      if (field) {
        std::array<double, D> gradient{};
        if (!solve_small<D>(A, g, gradient)) return;  // too few fluid neighbours to tell a gradient
        for (int d = 0; d < D; ++d) drho += gradient[d] * shift[d][a];
      } else {
        drho = mass * continuity;
      }
      change[a] = static_cast<float>(drho);
    });
  });
}

template <int D>
void smooth_shifting_density_change(const Particles<D>& p, const CellGrid<D>& grid, const FluidSettings<D>& s,
                                    const PairFilter<D>& filter, std::vector<float>& change, std::vector<float>& raw,
                                    std::size_t begin, std::size_t end) {
  raw = change;
  const bool filtered = filter.active();
  const float support2 = static_cast<float>(s.support_radius() * s.support_radius());
  with_kernel<D>(s.kernel, s.smoothing_length(), [&](const auto& W) {
    for_each_particle_with_neighbours<D>(grid, [&](std::uint32_t a, const auto& segments, int count) {
      if (a < begin || a >= end || p.kind[a] != Kind::fluid) return;
      double sum = 0.0, weight = 0.0;
      for (int k = 0; k < count; ++k) {
        const auto& seg = segments[k];
        for (std::uint32_t b = seg.begin; b < seg.end; ++b) {
          if (p.kind[b] != Kind::fluid) continue;
          float r2 = 0.0f;
          for (int d = 0; d < D; ++d) {
            const float dx = p.local_position[d][a] - (p.local_position[d][b] + static_cast<float>(seg.shift[d]));
            r2 += dx * dx;
          }
          if (r2 >= support2) continue;
          if (filtered && filter.blocked(a, b)) continue;
          const double w = W.value(std::sqrt(r2)) * p.inverse_density[b];
          sum += w * raw[b];
          weight += w;
        }
      }
      change[a] = weight > 0 ? static_cast<float>(sum / weight) : raw[a];
    });
  });
}

template void smooth_shifting_density_change<2>(const Particles<2>&, const CellGrid<2>&, const FluidSettings<2>&,
                                                const PairFilter<2>&, std::vector<float>&, std::vector<float>&, std::size_t,
                                                std::size_t);
template void smooth_shifting_density_change<3>(const Particles<3>&, const CellGrid<3>&, const FluidSettings<3>&,
                                                const PairFilter<3>&, std::vector<float>&, std::vector<float>&, std::size_t,
                                                std::size_t);
template void shifting_density_change<2>(const Particles<2>&, const CellGrid<2>&, const FluidSettings<2>&, const PairFilter<2>&,
                                         const std::array<std::vector<double>, 2>&, std::vector<float>&, std::size_t, std::size_t);
template void shifting_density_change<3>(const Particles<3>&, const CellGrid<3>&, const FluidSettings<3>&, const PairFilter<3>&,
                                         const std::array<std::vector<double>, 3>&, std::vector<float>&, std::size_t, std::size_t);

}  // namespace valvefsi::fluid
