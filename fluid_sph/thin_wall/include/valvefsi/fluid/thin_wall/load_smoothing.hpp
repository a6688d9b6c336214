#pragma once
// Smoothing of the leaflet's node loads before they go to the solid (docs/thin-leaflet.md,
// "Node-load noise"). The fluid's reaction on the leaflet arrives node by node from the virtual
// points each particle sees; next to the wall the weakly compressible pressure is noisy
// (+-5-10 kPa), so a single node of a 0.25 mm leaflet can carry tens of kPa over its area while
// its neighbours carry little. Each node's load is spread over the nodes within a radius along
// the surface (same connected piece, distance along the mesh edges), with weights
//   lambda_i = A_i K(d_i / r) (c + beta . (x_i - x_j)),
// K the biweight (1 - q^2)^2, c and beta chosen so that sum lambda_i = 1 and
// sum lambda_i (x_i - x_j) = 0: the total force and its moment about any point are those of
// the unsmoothed loads, exactly (action = reaction with the fluid is kept as a whole).
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "valvefsi/fluid/thin_wall/triangle_mesh.hpp"

namespace valvefsi::fluid::thin_wall {

class NodeLoadSmoother {
 public:
  NodeLoadSmoother() = default;  // no smoothing: apply copies the loads
  // nodes: reference positions (the neighbourhoods are found once, along the mesh's edges);
  // areas: each node's share of the surface; radius > 0 (m).
  NodeLoadSmoother(std::span<const Vec3> nodes, std::span<const std::array<std::uint32_t, 3>> triangles,
                   std::span<const double> areas, double radius);

  // smoothed[i] = sum_j lambda_ij raw[j], the weights' first moments taken at the current
  // positions (so the moment is conserved in the deformed configuration).
  void apply(std::span<const Vec3> positions, std::span<const Vec3> raw, std::span<Vec3> smoothed) const;

  double radius() const { return radius_; }
  // Nodes a load is spread over, on average (1 without smoothing).
  double mean_neighbours() const;

 private:
  struct Neighbour {
    std::uint32_t node;
    double weight;  // A_i K(d_i / r)
  };
  double radius_ = 0.0;
  std::vector<std::vector<Neighbour>> spread_;  // per source node (empty: no smoothing)
};

}  // namespace valvefsi::fluid::thin_wall
