#pragma once
// The one loop over neighbours that every interaction pass shares: cells in parallel
// (OpenMP), then for each particle of a cell the unit-stride neighbour segments.
#include <cstddef>

#include "valvefsi/fluid/cell_grid.hpp"

namespace valvefsi::fluid {

// Cells are shared out in chunks of this many (one thread takes a whole chunk): a sum that must not
// depend on the thread schedule is booked per chunk (cell / kCellChunk) and summed in order.
inline constexpr std::size_t kCellChunk = 32;

// body(a, segments, segment_count) is called once for every particle a (sorted index).
template <int D, class Body>
void for_each_particle_with_neighbours(const CellGrid<D>& grid, Body&& body) {
  const auto cells = static_cast<std::ptrdiff_t>(grid.cell_count());
#pragma omp parallel
  {
    std::array<NeighbourSegment<D>, (D == 2 ? 9 : 27)> segments;
#pragma omp for schedule(dynamic, kCellChunk)
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

namespace valvefsi::fluid {

// Lanes for the SIMD block passes. Along each row of cells (x), the particles `wanted(a)`
// selects are taken in sorted order in blocks of up to BlockSize that span at most two
// adjacent cells, and body(lanes, n, segments, segment_count, row) gets each block with the
// neighbour segments of its cells and the index of its row (rows are shared out dynamically,
// so a sum that must not depend on the thread schedule is booked per row, not per thread). Full blocks across cell borders waste no padded lanes (a
// cell holds ~18 particles in 3D), and only the wanted particles (fluid for the rates, walls
// for the wall state) take lanes. Orphaned worksharing: call it inside a parallel region.
template <int D, int BlockSize, class Wanted, class Body>
void for_each_lane_block(const CellGrid<D>& grid, Wanted&& wanted, Body&& body) {
  const std::size_t nx = static_cast<std::size_t>(grid.cells_along(0));
  const auto rows = static_cast<std::ptrdiff_t>(grid.cell_count() / nx);
  std::array<NeighbourSegment<D>, (D == 2 ? 9 : 27)> segments;
  std::uint32_t lanes[BlockSize];
#pragma omp for schedule(dynamic, 2)
  for (std::ptrdiff_t row = 0; row < rows; ++row) {
    const std::size_t row_first = static_cast<std::size_t>(row) * nx;
    if (grid.cell_start(row_first) == grid.cell_start(row_first + nx)) continue;
    int n = 0;
    std::size_t first_cell = row_first, last_cell = row_first;
    auto flush = [&]() {
      const int count = grid.neighbour_segments(first_cell, last_cell, segments);
      body(static_cast<const std::uint32_t*>(lanes), n, segments, count, row);
      n = 0;
    };
    for (std::size_t c = row_first; c < row_first + nx; ++c) {
      const std::uint32_t last = grid.cell_start(c + 1);
      for (std::uint32_t a = grid.cell_start(c); a < last; ++a) {
        if (!wanted(a)) continue;
        if (n > 0 && c > first_cell + 1) flush();
        if (n == 0) first_cell = c;
        last_cell = c;
        lanes[n++] = a;
        if (n == BlockSize) flush();
      }
    }
    if (n > 0) flush();
  }
}

}  // namespace valvefsi::fluid
