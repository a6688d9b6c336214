#include "valvefsi/fluid/cell_grid.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace valvefsi::fluid {

template <int D>
CellGrid<D>::CellGrid(const Vec<D>& lower, const Vec<D>& upper, double min_cell_size,
                      const std::array<bool, D>& periodic)
    : lower_(lower), upper_(upper), periodic_(periodic) {
  cell_count_ = 1;
  for (int d = 0; d < D; ++d) {
    const double length = upper[d] - lower[d];
    if (!(length > 0)) throw std::invalid_argument("CellGrid: domain upper bound must exceed lower bound on axis " + std::to_string(d));
    counts_[d] = std::max(1, static_cast<int>(std::floor(length / min_cell_size)));
    if (periodic[d] && counts_[d] < 3)
      throw std::invalid_argument("CellGrid: periodic axis " + std::to_string(d) + " of length " + std::to_string(length) +
                                  " m must be at least 3 kernel supports (" + std::to_string(3 * min_cell_size) + " m)");
    size_[d] = length / counts_[d];
    inv_size_[d] = 1.0 / size_[d];
    cell_count_ *= static_cast<std::size_t>(counts_[d]);
  }
  start_.assign(cell_count_ + 2, 0);
}

template <int D>
std::size_t CellGrid<D>::cell_of(const Particles<D>& p, std::size_t i) const {
  if (p.kind[i] == Kind::lost) return cell_count_;
  std::size_t c = 0;
  for (int d = D - 1; d >= 0; --d) {
    int k = static_cast<int>((p.position[d][i] - lower_[d]) * inv_size_[d]);
    k = std::clamp(k, 0, counts_[d] - 1);  // round-off at the upper edge
    c = c * static_cast<std::size_t>(counts_[d]) + static_cast<std::size_t>(k);
  }
  return c;
}

template <int D>
void CellGrid<D>::set_cell_starts(std::vector<std::uint32_t> starts) {
  if (starts.size() != start_.size())
    throw std::invalid_argument("CellGrid: " + std::to_string(starts.size()) + " cell starts for a grid of " +
                                std::to_string(start_.size()) + " (another domain or spacing?)");
  start_ = std::move(starts);
}

template <int D>
bool CellGrid<D>::wrap_or_mark_lost(Particles<D>& p, std::size_t i) const {
  if (p.kind[i] == Kind::lost) return false;
  bool inside = true;
  for (int d = 0; d < D; ++d) {
    double& x = p.position[d][i];
    if (!std::isfinite(x)) {
      inside = false;
    } else if (periodic_[d]) {
      const double length = upper_[d] - lower_[d];
      if (x < lower_[d]) x += length * std::ceil((lower_[d] - x) / length);
      if (x >= upper_[d]) x -= length * std::floor((x - lower_[d]) / length);
    } else if (x < lower_[d] || x >= upper_[d]) {
      inside = false;
    }
  }
  if (inside) return false;
  p.kind[i] = Kind::lost;
  return true;
}

template <int D>
std::size_t CellGrid<D>::wrap_and_mark_lost(Particles<D>& p) const {
  const std::ptrdiff_t n = static_cast<std::ptrdiff_t>(p.size());
  std::size_t newly_lost = 0;
#pragma omp parallel for reduction(+ : newly_lost) schedule(static)
  for (std::ptrdiff_t i = 0; i < n; ++i) newly_lost += wrap_or_mark_lost(p, static_cast<std::size_t>(i)) ? 1 : 0;
  return newly_lost;
}

template <int D>
void CellGrid<D>::sort(Particles<D>& p) {
  const std::size_t n = p.size();
  const std::size_t buckets = cell_count_ + 1;
  cell_index_.resize(n);
  order_.resize(n);
  const int threads = omp_get_max_threads();
  thread_counts_.assign(static_cast<std::size_t>(threads) * buckets, 0);

  // Each thread counts a contiguous chunk, so the scatter below stays stable and parallel.
#pragma omp parallel num_threads(threads)
  {
    const int t = omp_get_thread_num();
    const int nt = omp_get_num_threads();
    const std::size_t lo = n * static_cast<std::size_t>(t) / static_cast<std::size_t>(nt);
    const std::size_t hi = n * static_cast<std::size_t>(t + 1) / static_cast<std::size_t>(nt);
    std::uint32_t* counts = thread_counts_.data() + static_cast<std::size_t>(t) * buckets;
    for (std::size_t i = lo; i < hi; ++i) {
      const auto c = static_cast<std::uint32_t>(cell_of(p, i));
      cell_index_[i] = c;
      ++counts[c];
    }
#pragma omp barrier
#pragma omp single
    {
      std::uint32_t running = 0;
      for (std::size_t c = 0; c < buckets; ++c) {
        start_[c] = running;
        for (int tt = 0; tt < nt; ++tt) {
          std::uint32_t& k = thread_counts_[static_cast<std::size_t>(tt) * buckets + c];
          const std::uint32_t count = k;
          k = running;  // becomes this thread's write offset for cell c
          running += count;
        }
      }
      start_[buckets] = running;
    }
    for (std::size_t i = lo; i < hi; ++i) order_[counts[cell_index_[i]]++] = static_cast<std::uint32_t>(i);
  }

  p.for_each_sorted_array_with(sorted_, [n](auto&, auto& target) { target.resize(n); });
  for (int d = 0; d < D; ++d) p.local_position[d].resize(n);
  p.fluid_mask.resize(n);
  p.inverse_density.resize(n);
  p.near_fluid.resize(n);
  p.near_wall.resize(n);
  // One parallel region for all arrays: the gathers share no barrier until the end.
#pragma omp parallel
  {
    p.for_each_sorted_array_with(sorted_, [this, n](auto& source, auto& target) {
#pragma omp for schedule(static) nowait
      for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(n); ++i) target[i] = source[order_[i]];
    });
#pragma omp barrier
#pragma omp for schedule(static)
    for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(n); ++i) {
      for (int d = 0; d < D; ++d) p.local_position[d][i] = static_cast<float>(sorted_.position[d][i] - lower_[d]);
      const bool fluid = acts_as_fluid(sorted_.kind[i]);
      p.fluid_mask[i] = fluid ? 1.0f : 0.0f;
      // Not carried along (for_each_sorted_array_with): a fluid particle's is its velocity.
      if (fluid)
        for (int d = 0; d < D; ++d) p.viscous_velocity[d][i] = sorted_.velocity[d][i];
    }
  }
  p.for_each_sorted_array_with(sorted_, [](auto& a, auto& b) { a.swap(b); });
}

template <int D>
int CellGrid<D>::neighbour_segments(std::size_t cell, std::size_t last_cell,
                                    std::array<NeighbourSegment<D>, (D == 2 ? 9 : 27)>& out) const {
  const int last_x = static_cast<int>(last_cell % static_cast<std::size_t>(counts_[0]));
  std::array<int, D> c{};
  std::size_t rest = cell;
  for (int d = 0; d < D; ++d) {
    c[d] = static_cast<int>(rest % static_cast<std::size_t>(counts_[d]));
    rest /= static_cast<std::size_t>(counts_[d]);
  }
  int produced = 0;
  constexpr int rows = D == 2 ? 3 : 9;
  for (int r = 0; r < rows; ++r) {
    // Row offsets on axes 1..D-1.
    std::array<int, D> index = c;
    std::array<double, D> shift{};
    bool valid = true;
    int code = r;
    for (int d = 1; d < D; ++d) {
      int k = c[d] + (code % 3) - 1;
      code /= 3;
      if (k < 0 || k >= counts_[d]) {
        if (!periodic_[d]) { valid = false; break; }
        const double length = upper_[d] - lower_[d];
        shift[d] = k < 0 ? -length : length;
        k = k < 0 ? k + counts_[d] : k - counts_[d];
      }
      index[d] = k;
    }
    if (!valid) continue;
    std::size_t row_base = 0;
    for (int d = D - 1; d >= 1; --d) row_base = row_base * static_cast<std::size_t>(counts_[d]) + static_cast<std::size_t>(index[d]);
    row_base *= static_cast<std::size_t>(counts_[0]);
    // Along x: the in-range part is one contiguous segment; wrapped cells are their own.
    const int x_lo = std::max(c[0] - 1, 0);
    const int x_hi = std::min(last_x + 1, counts_[0] - 1);
    out[produced++] = {start_[row_base + x_lo], start_[row_base + x_hi + 1], shift};
    if (periodic_[0]) {
      const double length = upper_[0] - lower_[0];
      if (c[0] - 1 < 0) {
        auto s = shift;
        s[0] = -length;
        const std::size_t cc = row_base + counts_[0] - 1;
        out[produced++] = {start_[cc], start_[cc + 1], s};
      }
      if (last_x + 1 >= counts_[0]) {
        auto s = shift;
        s[0] = length;
        out[produced++] = {start_[row_base], start_[row_base + 1], s};
      }
    }
  }
  return produced;
}

template class CellGrid<2>;
template class CellGrid<3>;

}  // namespace valvefsi::fluid
