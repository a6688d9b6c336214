#pragma once
// Uniform cell list whose cells are at least one kernel support wide, and the counting sort
// that orders particles by cell. After sorting, a cell's particles are contiguous and so are
// the three cells of a row along x, so a particle's neighbours come as 3^(D-1) unit-stride
// segments (each with the periodic image shift to add to the neighbour's position).
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "valvefsi/fluid/particles.hpp"

namespace valvefsi::fluid {

template <int D>
struct NeighbourSegment {
  std::uint32_t begin;
  std::uint32_t end;
  std::array<double, D> shift;  // added to the neighbour's position (periodic images)
};

template <int D>
class CellGrid {
 public:
  // Cells tile [lower, upper); each axis gets floor(length / min_cell_size) cells (at least 1).
  // Periodic axes need at least 3 cells so that no neighbour cell is visited twice.
  CellGrid(const Vec<D>& lower, const Vec<D>& upper, double min_cell_size, const std::array<bool, D>& periodic);

  std::size_t cell_count() const { return cell_count_; }
  int cells_along(int axis) const { return counts_[axis]; }
  double cell_size(int axis) const { return size_[axis]; }
  const Vec<D>& lower() const { return lower_; }
  const Vec<D>& upper() const { return upper_; }
  const std::array<bool, D>& periodic() const { return periodic_; }

  // Wraps positions on periodic axes into [lower, upper) and marks particles outside a
  // non-periodic axis (or not finite) as Kind::lost. Returns how many became lost now.
  std::size_t wrap_and_mark_lost(Particles<D>& particles) const;
  // The same for particle i alone (true if it became lost now), for passes that move it.
  bool wrap_or_mark_lost(Particles<D>& particles, std::size_t i) const;

  // Stable counting sort of the particle arrays a sort carries (Particles::for_each_sorted_array_with)
  // by cell; lost particles go to the end. Sets the pair loops' scratch and, for fluid, the
  // viscous velocity (= velocity).
  void sort(Particles<D>& particles);

  // First particle of cell c; cell_start(cell_count()) is the first lost particle.
  std::uint32_t cell_start(std::size_t c) const { return start_[c]; }

  std::size_t cell_of(const Particles<D>& particles, std::size_t i) const;

  // The cell ranges of the last sort (cell_count() + 2 entries), for restart files; the
  // setter throws std::invalid_argument on a wrong size.
  const std::vector<std::uint32_t>& cell_starts() const { return start_; }
  void set_cell_starts(std::vector<std::uint32_t> starts);

  // Up to 3^(D-1) * 3 segments covering the cell's neighbour cells; returns how many.
  int neighbour_segments(std::size_t cell, std::array<NeighbourSegment<D>, (D == 2 ? 9 : 27)>& out) const {
    return neighbour_segments(cell, cell, out);
  }
  // The same for the cells first_cell..last_cell of one row along x (last_cell >= first_cell,
  // same row): the neighbour rows span x from first - 1 to last + 1.
  int neighbour_segments(std::size_t first_cell, std::size_t last_cell,
                         std::array<NeighbourSegment<D>, (D == 2 ? 9 : 27)>& out) const;

 private:
  Vec<D> lower_{}, upper_{}, size_{}, inv_size_{};
  std::array<int, D> counts_{};
  std::array<bool, D> periodic_{};
  std::size_t cell_count_ = 0;
  std::vector<std::uint32_t> start_;      // cell_count_ + 2 entries
  std::vector<std::uint32_t> cell_index_;  // per particle (scratch)
  std::vector<std::uint32_t> order_;       // gather order (scratch)
  std::vector<std::uint32_t> thread_counts_;
  Particles<D> sorted_;                    // gather target, swapped with the particles
};

}  // namespace valvefsi::fluid
