#pragma once
// Markers: the fluid's point cloud on the thin wall. Each segment is cut into
// max(1, round(length / spacing)) equal pieces and a marker sits at every piece's midpoint
// with the piece's length as its area (per unit depth in 2D), so the areas sum exactly to the
// wall's length. A marker carries one wall state per side (extrapolated from that side's fluid)
// and accumulates the force the fluid exerts on it. Wall quantities at any point of the wall
// are interpolated linearly in arc length between the two nearest markers; the same weights
// spread a force at a point back onto the markers, so the two operations are transposes and
// momentum is conserved exactly.
#include <array>
#include <cstddef>
#include <vector>

#include "valvefsi/fluid/thin_wall/polyline.hpp"

namespace valvefsi::fluid::thin_wall {

struct SideState {
  double pressure = 0.0;           // Pa (includes the background pressure, as the fluid's)
  Vec2 extrapolated_velocity{};    // Shepard average of that side's fluid velocity
  double weight = 0.0;             // Shepard denominator sum W (0: no fluid on that side)
};

struct Marker {
  std::size_t segment = 0;
  double t = 0.0;           // parameter on the segment
  double arc_length = 0.0;  // from the first node
  double area = 0.0;        // m (2D: per unit depth)
  std::array<SideState, 2> side;  // index 0: side -1, index 1: side +1
  Vec2 force{};             // of the fluid on the marker (N per unit depth), both sides
};

inline int side_index(int side) { return side > 0 ? 1 : 0; }

// The two markers bracketing a wall point and their weights (w0 + w1 = 1).
struct MarkerWeights {
  std::size_t first = 0, second = 0;
  double w0 = 1.0, w1 = 0.0;
};

class MarkerSet {
 public:
  MarkerSet() = default;
  // Samples markers at about `spacing` on the wall (spacing > 0).
  MarkerSet(const Polyline& wall, double spacing);

  std::size_t size() const { return markers_.size(); }
  Marker& operator[](std::size_t m) { return markers_[m]; }
  const Marker& operator[](std::size_t m) const { return markers_[m]; }
  std::vector<Marker>& markers() { return markers_; }
  const std::vector<Marker>& markers() const { return markers_; }
  double total_length() const { return segment_start_.back(); }

  // Arc length of the material wall point (segment, t), measured in the configuration the
  // markers were sampled in, so that markers and queries agree while the wall deforms.
  double arc_length(std::size_t segment, double t) const;
  MarkerWeights weights_at(double arc_length) const;
  // Force summed over all markers.
  Vec2 total_force() const;
  // Marker forces lumped onto the wall's nodes (what the coupler receives): each marker's
  // force split between its segment's two nodes by its parameter t.
  std::vector<Vec2> node_forces(std::size_t node_count) const;

 private:
  std::vector<Marker> markers_;
  std::vector<double> segment_start_;  // arc length at each node
};

}  // namespace valvefsi::fluid::thin_wall
