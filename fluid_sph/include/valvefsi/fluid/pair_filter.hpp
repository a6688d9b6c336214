#pragma once
// Which particle pairs an immersed surface (a leaflet) separates. The pair loops consult it
// only for pairs with a near-surface particle, so a run without a surface, and every cell far
// from one, keeps the unfiltered SIMD path.
#include <cstdint>

#include "valvefsi/fluid/cell_grid.hpp"
#include "valvefsi/fluid/immersed_surface.hpp"
#include "valvefsi/fluid/particles.hpp"

namespace valvefsi::fluid {

template <int D>
struct PairFilter {
  const ImmersedSurfaceModel<D>* surface = nullptr;
  const Particles<D>* particles = nullptr;
  const std::uint8_t* near = nullptr;  // per sorted particle: 1 if within a support of the surface

  bool active() const { return surface != nullptr; }
  bool is_near(std::uint32_t i) const { return near[i] != 0; }
  bool blocked(std::uint32_t a, std::uint32_t b) const {
    return (near[a] | near[b]) != 0 && surface->blocked(a, b, *particles);
  }
  // Whether any particle of the neighbour segments is near the surface (then pairs of this
  // cell may be blocked and need the filtered path).
  template <class Segments>
  bool touches(const Segments& segments, int count) const {
    if (!active()) return false;
    for (int s = 0; s < count; ++s)
      for (std::uint32_t b = segments[s].begin; b < segments[s].end; ++b)
        if (near[b] != 0) return true;
    return false;
  }
};

}  // namespace valvefsi::fluid
