#pragma once
// Images of images where mirror planes meet. Reflections in planes that cross (a sector's two
// cut faces meet at its axis) generate a finite group when the planes meet at 180/n degrees:
// the dihedral group of order 2n (6 for a 60-degree sector). Near the meeting line a particle
// needs its image under every element of that group, not only under each plane's reflection,
// or the fluid there misses neighbours (a column at the axis accelerates inward).
#include <array>
#include <cstddef>
#include <vector>

#include "valvefsi/fluid/fluid_settings.hpp"

namespace valvefsi::fluid {

// An isometry x' = M x + t (a product of reflections).
template <int D>
struct MirrorMap {
  std::array<Vec<D>, D> matrix{};  // rows of M
  Vec<D> shift{};                  // t (m)

  Vec<D> apply(const Vec<D>& x) const {
    Vec<D> y = shift;
    for (int r = 0; r < D; ++r)
      for (int c = 0; c < D; ++c) y[r] += matrix[r][c] * x[c];
    return y;
  }
  Vec<D> rotate(const Vec<D>& v) const {  // the linear part, for velocities
    Vec<D> y{};
    for (int r = 0; r < D; ++r)
      for (int c = 0; c < D; ++c) y[r] += matrix[r][c] * v[c];
    return y;
  }
};

// The elements of the group the planes' reflections generate other than the identity and the
// planes' own reflections (those are the single images): the compound images. Empty for one
// plane or for planes that are all parallel (their images of images lie farther than the plane
// spacing from the fluid). Throws std::invalid_argument, naming the planes and their angles,
// when two crossing planes bound a wedge that is not 180/n degrees (its images would overlap the
// fluid) or when the group has more than max_order elements (parallel planes together with one
// that crosses them generate an infinite group).
template <int D>
std::vector<MirrorMap<D>> compound_mirror_maps(const std::vector<MirrorPlane<D>>& planes, std::size_t max_order = 48);

// How many copies of the fluid the planes' reflections make of the whole (the order of the group
// they generate: 1 without planes, 2 for one plane, 6 for a 60-degree sector): the factor from a
// part's flows and forces to the whole's. 0 when there is no finite whole (parallel planes: a
// strip between mirror walls). Throws as compound_mirror_maps does for planes that never close.
template <int D>
double mirror_symmetry_factor(const std::vector<MirrorPlane<D>>& planes);

}  // namespace valvefsi::fluid
