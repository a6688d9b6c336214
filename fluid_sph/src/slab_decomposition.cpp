#include "valvefsi/fluid/slab_decomposition.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

namespace valvefsi::fluid {
namespace {

// Keeps the entries at the (increasing) indices `keep` of every per-particle array, in order.
template <int D>
void compact(Particles<D>& p, const std::vector<std::uint32_t>& keep) {
  p.for_each_array([&](auto& a) {
    for (std::size_t j = 0; j < keep.size(); ++j) a[j] = a[keep[j]];
    a.resize(keep.size());
  });
}

template <int D>
void append_particle(Particles<D>& from, std::size_t i, Particles<D>& to) {
  from.for_each_array_with(to, [i](auto& source, auto& target) { target.push_back(source[i]); });
}

template <int D>
void append_all(Particles<D>& from, Particles<D>& to) {
  from.for_each_array_with(to, [](auto& source, auto& target) { target.insert(target.end(), source.begin(), source.end()); });
}

template <int D>
void clear(Particles<D>& p) {
  p.for_each_array([](auto& a) { a.clear(); });
}

}  // namespace

template <int D>
SlabDecomposition<D>::SlabDecomposition(MPI_Comm comm, const CellGrid<D>& grid, const Particles<D>& p) : comm_(comm) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  layers_ = grid.cells_along(kAxis);
  layer_cells_ = grid.cell_count() / static_cast<std::size_t>(layers_);
  lower_ = grid.lower()[kAxis];
  inv_size_ = 1.0 / grid.cell_size(kAxis);
  if (size_ > 1 && grid.periodic()[kAxis])
    throw std::invalid_argument(fmt::format("fluid MPI decomposition: the slab axis ({}) is periodic; run a periodic "
                                            "axis {} case on one rank", kAxis, kAxis));
  // Cuts where the running cost passes r / size of the total, then widened so every slab holds
  // at least the halo's layers (its halo must come from its neighbours only). Cost: a fluid
  // particle 1, a wall particle 1/4 (the rates pass over the fluid takes ~4x the wall-state
  // pass per particle; profile of the 3D tube on 2 ranks: counting walls fully left rank 1
  // with 54 % of the rates and rank 0 waiting 30 % of its time).
  std::vector<double> count(static_cast<std::size_t>(layers_), 0.0);
  double total = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (is_mirror(p.kind[i]) || p.kind[i] == Kind::lost) continue;
    const double cost = p.kind[i] == Kind::fluid ? 1.0 : 0.25;
    count[static_cast<std::size_t>(layer_of(p.position[kAxis][i]))] += cost;
    total += cost;
  }
  std::vector<int> first(static_cast<std::size_t>(size_) + 1, 0);
  first[static_cast<std::size_t>(size_)] = layers_;
  double running = 0;
  int layer = 0;
  for (int r = 1; r < size_; ++r) {
    const double target = total * r / size_;
    while (layer < layers_ && running + count[static_cast<std::size_t>(layer)] <= target) running += count[static_cast<std::size_t>(layer++)];
    first[static_cast<std::size_t>(r)] = std::max(layer, first[static_cast<std::size_t>(r) - 1] + kHaloLayers);
  }
  for (int r = 0; r < size_; ++r)
    if (first[static_cast<std::size_t>(r) + 1] - first[static_cast<std::size_t>(r)] < kHaloLayers)
      throw std::invalid_argument(fmt::format("fluid MPI decomposition: {} ranks need at least {} cell layers along axis {}, "
                                              "the domain has {} (cells of {} m): use fewer ranks",
                                              size_, kHaloLayers * size_, kAxis, layers_, grid.cell_size(kAxis)));
  first_ = first[static_cast<std::size_t>(rank_)];
  last_ = first[static_cast<std::size_t>(rank_) + 1];
}

template <int D>
int SlabDecomposition<D>::layer_of(double coordinate) const {
  const int k = static_cast<int>((coordinate - lower_) * inv_size_);
  return std::clamp(k, 0, layers_ - 1);
}

template <int D>
void SlabDecomposition<D>::keep_own_and_halo(Particles<D>& p) const {
  std::vector<std::uint32_t> keep;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (is_mirror(p.kind[i]) || p.kind[i] == Kind::lost) continue;
    const int k = layer_of(p.position[kAxis][i]);
    if (k >= first_ - kHaloLayers && k < last_ + kHaloLayers) keep.push_back(static_cast<std::uint32_t>(i));
  }
  compact(p, keep);
}

template <int D>
void SlabDecomposition<D>::drop_halo(Particles<D>& p, std::size_t owned_begin, std::size_t owned_end) const {
  std::vector<std::uint32_t> keep;
  keep.reserve(owned_end - owned_begin);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const bool owned = i >= owned_begin && i < owned_end && !is_mirror(p.kind[i]);
    if (owned || p.kind[i] == Kind::lost) keep.push_back(static_cast<std::uint32_t>(i));
  }
  compact(p, keep);
}

template <int D>
void SlabDecomposition<D>::send_receive(Particles<D>& send, Particles<D>& receive, int destination, int source) const {
  unsigned long long outgoing = send.size(), incoming = 0;
  MPI_Sendrecv(&outgoing, 1, MPI_UNSIGNED_LONG_LONG, destination, 1, &incoming, 1, MPI_UNSIGNED_LONG_LONG, source, 1, comm_,
               MPI_STATUS_IGNORE);
  int tag = 2;
  send.for_each_array_with(receive, [&](auto& mine, auto& theirs) {
    using T = typename std::decay_t<decltype(mine)>::value_type;
    theirs.resize(incoming);
    MPI_Sendrecv(mine.data(), static_cast<int>(mine.size() * sizeof(T)), MPI_BYTE, destination, tag, theirs.data(),
                 static_cast<int>(incoming * sizeof(T)), MPI_BYTE, source, tag, comm_, MPI_STATUS_IGNORE);
    ++tag;
  });
}

template <int D>
void SlabDecomposition<D>::migrate_and_share_halo(Particles<D>& p) {
  const int left = rank_ > 0 ? rank_ - 1 : MPI_PROC_NULL;
  const int right = rank_ + 1 < size_ ? rank_ + 1 : MPI_PROC_NULL;
  // Migration: a particle whose layer left the slab goes to that side's neighbour (a step
  // moves it far less than a layer). Lost particles stay where they were counted.
  clear(left_);
  clear(right_);
  std::vector<std::uint32_t> keep;
  keep.reserve(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    const int k = p.kind[i] == Kind::lost ? first_ : layer_of(p.position[kAxis][i]);
    if (k < first_ && left != MPI_PROC_NULL) append_particle(p, i, left_);
    else if (k >= last_ && right != MPI_PROC_NULL) append_particle(p, i, right_);
    else keep.push_back(static_cast<std::uint32_t>(i));
  }
  compact(p, keep);
  send_receive(right_, from_left_, right, left);
  send_receive(left_, from_right_, left, right);
  append_all(from_left_, p);
  append_all(from_right_, p);
  // Halo: copies of the own particles in the layers next to each neighbour.
  clear(left_);
  clear(right_);
  const std::size_t own = p.size();
  for (std::size_t i = 0; i < own; ++i) {
    if (p.kind[i] == Kind::lost) continue;
    const int k = layer_of(p.position[kAxis][i]);
    if (left != MPI_PROC_NULL && k < first_ + kHaloLayers) append_particle(p, i, left_);
    if (right != MPI_PROC_NULL && k >= last_ - kHaloLayers) append_particle(p, i, right_);
  }
  send_receive(right_, from_left_, right, left);
  send_receive(left_, from_right_, left, right);
  append_all(from_left_, p);
  append_all(from_right_, p);
}

template <int D>
std::pair<std::size_t, std::size_t> SlabDecomposition<D>::owned_range(const CellGrid<D>& grid) const {
  return {grid.cell_start(static_cast<std::size_t>(first_) * layer_cells_), grid.cell_start(static_cast<std::size_t>(last_) * layer_cells_)};
}

template <int D>
void SlabDecomposition<D>::sum(std::span<double> values) const {
  if (size_ > 1) MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, MPI_SUM, comm_);
}

template <int D>
double SlabDecomposition<D>::sum(double value) const {
  sum(std::span<double>(&value, 1));
  return value;
}

template <int D>
double SlabDecomposition<D>::max(double value) const {
  if (size_ > 1) MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_DOUBLE, MPI_MAX, comm_);
  return value;
}

template <int D>
std::vector<double> SlabDecomposition<D>::gather(std::span<const double> values) const {
  const int mine = static_cast<int>(values.size());
  std::vector<int> counts(static_cast<std::size_t>(size_), 0), offsets(static_cast<std::size_t>(size_), 0);
  MPI_Gather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm_);
  std::vector<double> all;
  if (rank_ == 0) {
    for (int r = 1; r < size_; ++r)
      offsets[static_cast<std::size_t>(r)] = offsets[static_cast<std::size_t>(r) - 1] + counts[static_cast<std::size_t>(r) - 1];
    all.resize(static_cast<std::size_t>(offsets.back() + counts.back()));
  }
  MPI_Gatherv(values.data(), mine, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, 0, comm_);
  return all;
}

template class SlabDecomposition<2>;
template class SlabDecomposition<3>;

}  // namespace valvefsi::fluid
