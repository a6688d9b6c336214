#include "valvefsi/fluid/mirror_group.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace valvefsi::fluid {
namespace {

template <int D>
MirrorMap<D> reflection(const MirrorPlane<D>& plane) {
  // x' = x - 2 ((x - p).n) n = (I - 2 n n^T) x + 2 (p.n) n
  MirrorMap<D> m;
  double pn = 0;
  for (int d = 0; d < D; ++d) pn += plane.point[d] * plane.normal[d];
  for (int r = 0; r < D; ++r) {
    for (int c = 0; c < D; ++c) m.matrix[r][c] = (r == c ? 1.0 : 0.0) - 2.0 * plane.normal[r] * plane.normal[c];
    m.shift[r] = 2.0 * pn * plane.normal[r];
  }
  return m;
}

// a after b: x -> a(b(x)).
template <int D>
MirrorMap<D> compose(const MirrorMap<D>& a, const MirrorMap<D>& b) {
  MirrorMap<D> c;
  c.shift = a.apply(b.shift);
  for (int r = 0; r < D; ++r)
    for (int k = 0; k < D; ++k)
      for (int col = 0; col < D; ++col) c.matrix[r][col] += a.matrix[r][k] * b.matrix[k][col];
  return c;
}

template <int D>
bool same(const MirrorMap<D>& a, const MirrorMap<D>& b, double length_scale) {
  // Matrix entries are O(1); shifts are compared relative to the planes' distance from the origin.
  double error = 0;
  for (int r = 0; r < D; ++r) {
    error += std::abs(a.shift[r] - b.shift[r]) / length_scale;
    for (int c = 0; c < D; ++c) error += std::abs(a.matrix[r][c] - b.matrix[r][c]);
  }
  return error < 1e-9;
}

}  // namespace

template <int D>
std::vector<MirrorMap<D>> compound_mirror_maps(const std::vector<MirrorPlane<D>>& planes, std::size_t max_order) {
  // Two crossing planes bound a wedge of angle pi - (angle between their normals towards the
  // fluid). Only a wedge of 180/n degrees tiles the space around its edge with its images; any
  // other angle would put images inside the fluid (or never close).
  bool crossing = false;
  for (std::size_t a = 0; a < planes.size(); ++a)
    for (std::size_t b = a + 1; b < planes.size(); ++b) {
      double cosine = 0;
      for (int d = 0; d < D; ++d) cosine += planes[a].normal[d] * planes[b].normal[d];
      if (std::abs(cosine) >= 1.0 - 1e-12) continue;
      crossing = true;
      const double wedge = std::numbers::pi - std::acos(cosine);
      const double n = std::numbers::pi / wedge;
      if (std::abs(n - std::round(n)) > 1e-6)
        throw std::invalid_argument(fmt::format(
            "mirror planes {} and {} bound a wedge of {:.6g} degrees: allowed 180/n degrees (90, 60, 45, 36, 30 ...), "
            "whose images tile the space around the line where the planes meet",
            a, b, wedge * 180.0 / std::numbers::pi));
    }
  if (!crossing) return {};

  double length_scale = 1.0;
  for (const auto& plane : planes)
    for (int d = 0; d < D; ++d) length_scale = std::max(length_scale, std::abs(plane.point[d]));
  std::vector<MirrorMap<D>> generators, group;
  for (const auto& plane : planes) generators.push_back(reflection(plane));
  MirrorMap<D> identity;
  for (int r = 0; r < D; ++r) identity.matrix[r][r] = 1.0;
  group.push_back(identity);
  // Closure: every element times every generator, until nothing new appears.
  for (std::size_t at = 0; at < group.size(); ++at) {
    for (const auto& g : generators) {
      const MirrorMap<D> product = compose(g, group[at]);
      bool known = false;
      for (const auto& h : group) known = known || same(h, product, length_scale);
      if (known) continue;
      group.push_back(product);
      if (group.size() > max_order) {
        std::string angles;
        for (std::size_t a = 0; a < planes.size(); ++a)
          for (std::size_t b = a + 1; b < planes.size(); ++b) {
            double cosine = 0;
            for (int d = 0; d < D; ++d) cosine += planes[a].normal[d] * planes[b].normal[d];
            const double degrees = std::acos(std::clamp(cosine, -1.0, 1.0)) * 180.0 / std::numbers::pi;
            angles += fmt::format("{}planes {} and {}: normals {:.6g} degrees apart", angles.empty() ? "" : "; ", a, b, degrees);
          }
        throw std::invalid_argument(fmt::format(
            "the reflections in the {} mirror planes generate more than {} images of a particle ({}): allowed planes "
            "that meet at 180/n degrees (a sector of 360/(2n) degrees: 90, 60, 45, 30 ...) or planes that are all "
            "parallel; parallel planes together with a crossing one, or an angle that is not 180/n, never close",
            planes.size(), max_order, angles));
      }
    }
  }
  std::vector<MirrorMap<D>> compound;
  for (const auto& g : group) {
    bool single = same(g, identity, length_scale);
    for (const auto& r : generators) single = single || same(g, r, length_scale);
    if (!single) compound.push_back(g);
  }
  return compound;
}

template <int D>
double mirror_symmetry_factor(const std::vector<MirrorPlane<D>>& planes) {
  for (std::size_t a = 0; a < planes.size(); ++a)
    for (std::size_t b = a + 1; b < planes.size(); ++b) {
      double cosine = 0;
      for (int d = 0; d < D; ++d) cosine += planes[a].normal[d] * planes[b].normal[d];
      if (std::abs(cosine) >= 1.0 - 1e-12) return 0.0;
    }
  // The identity, each plane's reflection and the compound images.
  return static_cast<double>(1 + planes.size() + compound_mirror_maps<D>(planes).size());
}

template double mirror_symmetry_factor<2>(const std::vector<MirrorPlane<2>>&);
template double mirror_symmetry_factor<3>(const std::vector<MirrorPlane<3>>&);
template std::vector<MirrorMap<2>> compound_mirror_maps<2>(const std::vector<MirrorPlane<2>>&, std::size_t);
template std::vector<MirrorMap<3>> compound_mirror_maps<3>(const std::vector<MirrorPlane<3>>&, std::size_t);

}  // namespace valvefsi::fluid
