#include "valvefsi/fluid/thin_wall/load_smoothing.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <stdexcept>
#include <utility>

namespace valvefsi::fluid::thin_wall {
namespace {

double distance(const Vec3& a, const Vec3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

// The biweight (1 - q^2)^2 of q = d / r: 1 at q = 0, 0 with its slope at q = 1; flatter than an
// SPH kernel, so a radius of a few node spacings averages over many nodes.
double biweight(double q) { return q >= 1.0 ? 0.0 : (1.0 - q * q) * (1.0 - q * q); }

}  // namespace

NodeLoadSmoother::NodeLoadSmoother(std::span<const Vec3> nodes, std::span<const std::array<std::uint32_t, 3>> triangles,
                                   std::span<const double> areas, double radius)
    : radius_(radius) {
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw std::invalid_argument(fmt::format("node load smoothing: radius {} m: allowed a positive finite length", radius));
  if (areas.size() != nodes.size())
    throw std::invalid_argument(fmt::format("node load smoothing: {} node areas for {} nodes: allowed one per node", areas.size(), nodes.size()));
  const std::size_t n = nodes.size();
  std::vector<std::vector<std::pair<std::uint32_t, double>>> edges(n);
  for (const auto& tri : triangles)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = tri[static_cast<std::size_t>(k)], b = tri[static_cast<std::size_t>((k + 1) % 3)];
      if (a >= n || b >= n)
        throw std::invalid_argument(fmt::format("node load smoothing: a triangle names node {}: allowed 0 to {}", std::max(a, b), n - 1));
      const double l = distance(nodes[a], nodes[b]);
      edges[a].push_back({b, l});
      edges[b].push_back({a, l});
    }
  // Distance along the mesh's edges (Dijkstra, cut at the radius): loads never jump between
  // leaflets or across a gap, however close the sheets come.
  spread_.resize(n);
  std::vector<double> best(n, std::numeric_limits<double>::infinity());
  std::vector<std::uint32_t> touched;
  using Item = std::pair<double, std::uint32_t>;
  for (std::uint32_t j = 0; j < n; ++j) {
    std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
    best[j] = 0.0;
    touched.assign(1, j);
    queue.push({0.0, j});
    while (!queue.empty()) {
      const auto [d, i] = queue.top();
      queue.pop();
      if (d > best[i]) continue;
      spread_[j].push_back({i, areas[i] * biweight(d / radius)});
      for (const auto& [k, l] : edges[i]) {
        const double dk = d + l;
        if (dk < radius && dk < best[k]) {
          if (best[k] == std::numeric_limits<double>::infinity()) touched.push_back(k);
          best[k] = dk;
          queue.push({dk, k});
        }
      }
    }
    for (const std::uint32_t i : touched) best[i] = std::numeric_limits<double>::infinity();
  }
}

double NodeLoadSmoother::mean_neighbours() const {
  if (spread_.empty()) return 1.0;
  std::size_t total = 0;
  for (const auto& s : spread_) total += s.size();
  return static_cast<double>(total) / static_cast<double>(spread_.size());
}

void NodeLoadSmoother::apply(std::span<const Vec3> positions, std::span<const Vec3> raw, std::span<Vec3> smoothed) const {
  if (raw.size() != smoothed.size() || (!spread_.empty() && (raw.size() != spread_.size() || positions.size() != spread_.size())))
    throw std::invalid_argument(fmt::format("node load smoothing: {} loads, {} positions, {} outputs: allowed one per node ({})", raw.size(),
                                            positions.size(), smoothed.size(), spread_.size()));
  if (spread_.empty()) {
    std::copy(raw.begin(), raw.end(), smoothed.begin());
    return;
  }
  std::fill(smoothed.begin(), smoothed.end(), Vec3{0, 0, 0});
  for (std::size_t j = 0; j < spread_.size(); ++j) {
    const Vec3& f = raw[j];
    if (f[0] == 0.0 && f[1] == 0.0 && f[2] == 0.0) continue;
    // Zeroth, first and second moments of the base weights about the source node.
    double s = 0.0;
    Eigen::Vector3d m = Eigen::Vector3d::Zero();
    Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
    for (const auto& [i, w] : spread_[j]) {
      const Eigen::Vector3d d(positions[i][0] - positions[j][0], positions[i][1] - positions[j][1], positions[i][2] - positions[j][2]);
      s += w;
      m += w * d;
      M += w * d * d.transpose();
    }
    // lambda_i = w_i (c + beta . d_i): c s + beta . m = 1 and c m + M beta = 0, so
    // beta = -c M^+ m. M is singular across a flat patch (and along a row of nodes at a
    // corner); there m has no component either, so the pseudo-inverse is exact.
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(M);
    const Eigen::Vector3d values = eigen.eigenvalues();
    const double cut = 1e-8 * std::max(values.cwiseAbs().maxCoeff(), std::numeric_limits<double>::min());
    Eigen::Vector3d inverse_values;
    for (int k = 0; k < 3; ++k) inverse_values[k] = std::abs(values[k]) > cut ? 1.0 / values[k] : 0.0;
    const Eigen::Vector3d Mm = eigen.eigenvectors() * inverse_values.asDiagonal() * eigen.eigenvectors().transpose() * m;
    const double denominator = s - m.dot(Mm);
    const double c = denominator > 1e-12 * s ? 1.0 / denominator : 1.0 / s;
    const Eigen::Vector3d beta = denominator > 1e-12 * s ? Eigen::Vector3d(-c * Mm) : Eigen::Vector3d::Zero();
    for (const auto& [i, w] : spread_[j]) {
      const Eigen::Vector3d d(positions[i][0] - positions[j][0], positions[i][1] - positions[j][1], positions[i][2] - positions[j][2]);
      const double lambda = w * (c + beta.dot(d));
      for (int k = 0; k < 3; ++k) smoothed[i][static_cast<std::size_t>(k)] += lambda * f[static_cast<std::size_t>(k)];
    }
  }
}

}  // namespace valvefsi::fluid::thin_wall
