#pragma once
// The one loop over neighbours that every interaction pass shares: cells in parallel
// (OpenMP), then for each particle of a cell the unit-stride neighbour segments.
#include <cstddef>

#include "valvefsi/fluid/cell_grid.hpp"

namespace valvefsi::fluid {

// body(a, segments, segment_count) is called once for every particle a (sorted index).
template <int D, class Body>
void for_each_particle_with_neighbours(const CellGrid<D>& grid, Body&& body) {
  const auto cells = static_cast<std::ptrdiff_t>(grid.cell_count());
#pragma omp parallel
  {
    std::array<NeighbourSegment<D>, (D == 2 ? 9 : 27)> segments;
#pragma omp for schedule(dynamic, 32)
    for (std::ptrdiff_t c = 0; c < cells; ++c) {
      const std::uint32_t first = grid.cell_start(static_cast<std::size_t>(c));
      const std::uint32_t last = grid.cell_start(static_cast<std::size_t>(c) + 1);
      if (first == last) continue;
      const int count = grid.neighbour_segments(static_cast<std::size_t>(c), segments);
      for (std::uint32_t a = first; a < last; ++a) body(a, segments, count);
    }
  }
}

}  // namespace valvefsi::fluid
