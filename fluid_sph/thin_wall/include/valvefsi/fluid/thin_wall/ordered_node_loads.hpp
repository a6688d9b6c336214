// The loads that fluid particles put on a leaflet's nodes (markers), summed in an order fixed by
// the particles' indices alone, so that a run does not depend on the thread count or schedule.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace valvefsi::fluid::thin_wall {

// The particles are cut into blocks of kParticleBlock consecutive indices. A thread books a whole
// block into its own dense buffer, then keeps only the nodes the block touched (a block of
// cell-sorted particles sees a handful of the leaflet's nodes) as that block's list. The lists are
// added in block order. Per-thread sums (the former way) made one and two threads differ in the
// last bit from the first step; a dense buffer per block would cost nodes x blocks doubles.
template <int D>
class OrderedNodeLoads {
 public:
  using Load = std::array<double, D>;
  static constexpr std::size_t kParticleBlock = 64;

  void reset(std::size_t node_count, std::size_t particle_count) {
    node_count_ = node_count;
    particle_count_ = particle_count;
    blocks_.resize((particle_count + kParticleBlock - 1) / kParticleBlock);
    for (auto& b : blocks_) b.clear();  // keeps the capacity between calls
  }
  std::size_t block_count() const { return blocks_.size(); }
  std::pair<std::size_t, std::size_t> block_range(std::size_t block) const {
    const std::size_t first = block * kParticleBlock;
    return {first, std::min(first + kParticleBlock, particle_count_)};
  }

  // One per thread: books the loads of the block it is working on.
  class Booking {
   public:
    explicit Booking(OrderedNodeLoads& loads)
        : loads_(loads), sum_(loads.node_count_, Load{}), touched_(loads.node_count_, 0) {}
    Load& at(std::uint32_t node) {
      if (!touched_[node]) {
        touched_[node] = 1;
        nodes_.push_back(node);
      }
      return sum_[node];
    }
    // Moves the block's sums into its list, in the order the nodes were first touched (each node
    // appears once per block, so that order does not change any node's total).
    void close_block(std::size_t block) {
      auto& list = loads_.blocks_[block];
      for (const std::uint32_t node : nodes_) {
        list.emplace_back(node, sum_[node]);
        sum_[node] = Load{};
        touched_[node] = 0;
      }
      nodes_.clear();
    }

   private:
    OrderedNodeLoads& loads_;
    std::vector<Load> sum_;
    std::vector<char> touched_;
    std::vector<std::uint32_t> nodes_;
  };

  // out[node] = the sum of the blocks' loads on it, added in block order.
  template <class Vector>
  void sum_into(std::vector<Vector>& out) const {
    out.assign(node_count_, Vector{});
    for (const auto& list : blocks_)
      for (const auto& [node, load] : list)
        for (int d = 0; d < D; ++d) out[node][d] += load[static_cast<std::size_t>(d)];
  }

 private:
  std::size_t node_count_ = 0, particle_count_ = 0;
  std::vector<std::vector<std::pair<std::uint32_t, Load>>> blocks_;
};

}  // namespace valvefsi::fluid::thin_wall
