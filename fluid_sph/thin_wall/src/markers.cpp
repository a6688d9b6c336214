#include "valvefsi/fluid/thin_wall/markers.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace valvefsi::fluid::thin_wall {

MarkerSet::MarkerSet(const Polyline& wall, double spacing) {
  if (!(spacing > 0)) throw std::invalid_argument("MarkerSet: spacing = " + std::to_string(spacing) + ": allowed > 0");
  segment_start_.assign(wall.node_count(), 0.0);
  for (std::size_t k = 0; k < wall.segment_count(); ++k) {
    const double length = wall.segment_length(k);
    segment_start_[k + 1] = segment_start_[k] + length;
    const int pieces = std::max(1, static_cast<int>(std::lround(length / spacing)));
    for (int i = 0; i < pieces; ++i) {
      Marker m;
      m.segment = k;
      m.t = (i + 0.5) / pieces;
      m.arc_length = segment_start_[k] + m.t * length;
      m.area = length / pieces;
      markers_.push_back(m);
    }
  }
}

double MarkerSet::arc_length(std::size_t segment, double t) const {
  return segment_start_[segment] + t * (segment_start_[segment + 1] - segment_start_[segment]);
}

MarkerWeights MarkerSet::weights_at(double s) const {
  MarkerWeights w;
  if (markers_.size() == 1 || s <= markers_.front().arc_length) return {0, 0, 1.0, 0.0};
  if (s >= markers_.back().arc_length) return {markers_.size() - 1, markers_.size() - 1, 1.0, 0.0};
  const auto it = std::upper_bound(markers_.begin(), markers_.end(), s,
                                   [](double value, const Marker& m) { return value < m.arc_length; });
  w.second = static_cast<std::size_t>(it - markers_.begin());
  w.first = w.second - 1;
  const double a = markers_[w.first].arc_length, b = markers_[w.second].arc_length;
  w.w1 = (s - a) / (b - a);
  w.w0 = 1.0 - w.w1;
  return w;
}

Vec2 MarkerSet::total_force() const {
  Vec2 f{0.0, 0.0};
  for (const auto& m : markers_) {
    f[0] += m.force[0];
    f[1] += m.force[1];
  }
  return f;
}

std::vector<Vec2> MarkerSet::node_forces(std::size_t node_count) const {
  std::vector<Vec2> f(node_count, Vec2{0.0, 0.0});
  for (const auto& m : markers_) {
    for (int d = 0; d < 2; ++d) {
      f[m.segment][d] += (1.0 - m.t) * m.force[d];
      f[m.segment + 1][d] += m.t * m.force[d];
    }
  }
  return f;
}

}  // namespace valvefsi::fluid::thin_wall
