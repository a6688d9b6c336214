#include "valvefsi/fluid/probes.hpp"

#include <algorithm>
#include <cmath>
#include <span>

#include "valvefsi/fluid/kernels.hpp"

namespace valvefsi::fluid {
namespace {

// Signed distance of particle i from the plane, and whether it lies within the radius.
template <int D>
bool in_slab(const Particles<D>& p, std::size_t i, const ProbePlane<D>& plane, double half_thickness) {
  double along = 0, r2 = 0;
  Vec<D> rel;
  for (int d = 0; d < D; ++d) {
    rel[d] = p.position[d][i] - plane.point[d];
    along += rel[d] * plane.normal[d];
  }
  if (std::abs(along) >= half_thickness) return false;
  if (plane.radius <= 0) return true;
  for (int d = 0; d < D; ++d) {
    const double perp = rel[d] - along * plane.normal[d];
    r2 += perp * perp;
  }
  return r2 <= plane.radius * plane.radius;
}

// Over ranks: the sum of the values (unchanged on one rank).
template <int D>
void sum_over_ranks(const FluidSolver<D>& solver, std::span<double> values) {
  if (solver.decomposition() != nullptr) solver.decomposition()->sum(values);
}

}  // namespace

// Every probe reads this rank's own particles and combines the ranks' parts (collective when
// the run is split over MPI ranks: every rank must call it).
template <int D>
double pressure_at(const FluidSolver<D>& solver, const Vec<D>& x) {
  const auto& p = solver.particles();
  const auto& s = solver.settings();
  const double support = s.support_radius();
  return with_kernel<D>(s.kernel, s.smoothing_length(), [&](const auto& W) {
    const auto [first, last] = solver.owned_range();
    double sums[2] = {0, 0};  // sum W, sum p W
    for (std::size_t i = first; i < last; ++i) {
      if (p.kind[i] != Kind::fluid) continue;
      double r2 = 0;
      for (int d = 0; d < D; ++d) {
        double dx = x[d] - p.position[d][i];
        if (s.periodic[d]) {
          const double length = s.domain_upper[d] - s.domain_lower[d];
          dx -= length * std::round(dx / length);
        }
        r2 += dx * dx;
      }
      if (r2 >= support * support) continue;
      const double w = W.value(static_cast<float>(std::sqrt(r2)));
      sums[0] += w;
      sums[1] += w * p.pressure[i];
    }
    sum_over_ranks<D>(solver, sums);
    return sums[0] > 0 ? sums[1] / sums[0] - s.background_pressure - solver.plate_pressure_level() : 0.0;
  });
}

template <int D>
double flow_rate(const FluidSolver<D>& solver, const ProbePlane<D>& plane) {
  const auto& p = solver.particles();
  const auto& s = solver.settings();
  const double dp = s.particle_spacing;
  double q = 0;
  const auto [first, last] = solver.owned_range();
  for (std::size_t i = first; i < last; ++i) {
    if (p.kind[i] != Kind::fluid || !in_slab<D>(p, i, plane, 0.5 * dp)) continue;
    double vn = 0;
    for (int d = 0; d < D; ++d) vn += p.velocity[d][i] * plane.normal[d];
    const double volume = s.particle_mass() / (s.rest_density + p.density_excess[i]);
    q += vn * volume / dp;
  }
  sum_over_ranks<D>(solver, std::span<double>(&q, 1));
  return q;
}

template <int D>
double max_speed_on_plane(const FluidSolver<D>& solver, const ProbePlane<D>& plane) {
  const auto& p = solver.particles();
  double best = 0;
  const auto [first, last] = solver.owned_range();
  for (std::size_t i = first; i < last; ++i) {
    if (p.kind[i] != Kind::fluid || !in_slab<D>(p, i, plane, 0.5 * solver.settings().particle_spacing)) continue;
    double v2 = 0;
    for (int d = 0; d < D; ++d) v2 += static_cast<double>(p.velocity[d][i]) * p.velocity[d][i];
    best = std::max(best, std::sqrt(v2));
  }
  return solver.decomposition() != nullptr ? solver.decomposition()->max(best) : best;
}

template <int D>
double kinetic_energy(const FluidSolver<D>& solver) {
  const auto& p = solver.particles();
  const double m = solver.settings().particle_mass();
  double e = 0;
  const auto [first, last] = solver.owned_range();
  for (std::size_t i = first; i < last; ++i) {
    if (p.kind[i] != Kind::fluid) continue;
    for (int d = 0; d < D; ++d) e += 0.5 * m * static_cast<double>(p.velocity[d][i]) * p.velocity[d][i];
  }
  sum_over_ranks<D>(solver, std::span<double>(&e, 1));
  return e;
}

template double pressure_at<2>(const FluidSolver<2>&, const Vec<2>&);
template double pressure_at<3>(const FluidSolver<3>&, const Vec<3>&);
template double flow_rate<2>(const FluidSolver<2>&, const ProbePlane<2>&);
template double flow_rate<3>(const FluidSolver<3>&, const ProbePlane<3>&);
template double max_speed_on_plane<2>(const FluidSolver<2>&, const ProbePlane<2>&);
template double max_speed_on_plane<3>(const FluidSolver<3>&, const ProbePlane<3>&);
template double kinetic_energy<2>(const FluidSolver<2>&);
template double kinetic_energy<3>(const FluidSolver<3>&);

}  // namespace valvefsi::fluid
