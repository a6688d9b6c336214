#pragma once
// MPI domain decomposition of the fluid into slabs of cell layers along the grid's last axis
// (z in 3D: the tube's axis; y in 2D). The cells are at least one kernel support wide, and the
// last axis is the grid's slowest, so a rank's own particles are one contiguous range after the
// sort. Each rank also holds a halo: copies of its neighbours' particles in the two cell layers
// next to its slab, enough for the wall state of the walls its own fluid sees (the Adami state
// of a wall reads the fluid within a support of it). Every step, after the drift: halos and
// mirror images are dropped, particles that left the slab migrate to the neighbour, and fresh
// halo copies are exchanged. Reductions (plate forces, maxima for the time step, counters,
// probes) go through this class so that results do not depend on the rank count beyond
// round-off (the order of floating-point sums).
#include <mpi.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "valvefsi/fluid/cell_grid.hpp"
#include "valvefsi/fluid/particles.hpp"

namespace valvefsi::fluid {

template <int D>
class SlabDecomposition {
 public:
  static constexpr int kAxis = D - 1;
  static constexpr int kHaloLayers = 2;

  // Cuts the grid's layers into comm's size slabs of about equal cost (fluid particles 1,
  // walls 1/4; mirror images and lost particles not counted). `particles`: the whole scene, the same on every
  // rank. Throws std::invalid_argument when a slab would be thinner than the halo (too many
  // ranks for the domain) or the last axis is periodic.
  SlabDecomposition(MPI_Comm comm, const CellGrid<D>& grid, const Particles<D>& particles);

  int rank() const { return rank_; }
  int size() const { return size_; }
  MPI_Comm communicator() const { return comm_; }
  int first_layer() const { return first_; }  // owned layers [first_layer, last_layer)
  int last_layer() const { return last_; }
  // Layer index along the axis of a position, as the grid computes it.
  int layer_of(double coordinate) const;

  // From the whole scene to this rank's own particles and its halo (mirror images and lost
  // particles dropped).
  void keep_own_and_halo(Particles<D>& particles) const;
  // After the drift: keeps this rank's particles (`owned_begin, owned_end`: the range of the
  // last sort, before the drift) and the lost ones; drops the halo and the mirror images.
  void drop_halo(Particles<D>& particles, std::size_t owned_begin, std::size_t owned_end) const;
  // Then: particles whose layer left the slab go to the neighbour on that side, and the halo
  // copies are exchanged and appended (collective).
  void migrate_and_share_halo(Particles<D>& particles);

  // Sorted-index range of the owned particles after a sort.
  std::pair<std::size_t, std::size_t> owned_range(const CellGrid<D>& grid) const;

  void sum(std::span<double> values) const;
  double sum(double value) const;
  double max(double value) const;
  // Gathers every rank's values on rank 0 in rank order (others get an empty vector).
  std::vector<double> gather(std::span<const double> values) const;

 private:
  void send_receive(Particles<D>& send, Particles<D>& receive, int destination, int source) const;
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  int first_ = 0, last_ = 0;
  int layers_ = 0;
  std::size_t layer_cells_ = 1;
  double lower_ = 0.0, inv_size_ = 1.0;
  Particles<D> scratch_, left_, right_, from_left_, from_right_;
};

}  // namespace valvefsi::fluid
