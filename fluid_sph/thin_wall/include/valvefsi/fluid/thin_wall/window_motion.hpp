#pragma once
// The surface nodes' motion through one coupling window [start_time, end_time]: the cubic
// Hermite curve through the start state (positions, velocities) and the coupler's end state.
// Exact for any motion that is cubic in time; gives the accelerations the wall condition
// needs. After end_time the nodes go on at their end velocity (no new target yet).
// Shared by the 2D (segments) and 3D (triangles) thin-wall models.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "valvefsi/fluid/thin_wall/restart_arrays.hpp"

namespace valvefsi::fluid::thin_wall {

template <int D>
class WindowMotionT {
 public:
  using V = std::array<double, D>;

  // Nodes at rest at `positions` at `time`.
  WindowMotionT(const std::vector<V>& positions, double time)
      : start_time_(time),
        end_time_(time),
        current_time_(time),
        x0_(positions),
        v0_(positions.size(), V{}),
        x1_(positions),
        v1_(positions.size(), V{}),
        x_(positions),
        v_(positions.size(), V{}) {}

  // The window starts at the last evaluated time (the construction time at first) from the
  // state there. Throws std::invalid_argument unless end_time > that time and the spans
  // have one entry per node.
  void set_target(double end_time, std::span<const V> end_positions, std::span<const V> end_velocities) {
    if (end_positions.size() != x_.size() || end_velocities.size() != x_.size())
      throw std::invalid_argument(
          fmt::format("thin wall window target: {} positions and {} velocities: allowed {} of each (one per node)",
                      end_positions.size(), end_velocities.size(), x_.size()));
    if (!(end_time > current_time_))
      throw std::invalid_argument(
          fmt::format("thin wall window target: end time {} s: allowed after the current time {} s", end_time, current_time_));
    start_time_ = current_time_;
    end_time_ = end_time;
    x0_ = x_;
    v0_ = v_;
    x1_.assign(end_positions.begin(), end_positions.end());
    v1_.assign(end_velocities.begin(), end_velocities.end());
  }

  // Position, velocity and acceleration of every node at `time`; the time becomes current.
  void evaluate(double time, std::vector<V>& x, std::vector<V>& v, std::vector<V>& a) {
    const std::size_t n = x_.size();
    x.resize(n);
    v.resize(n);
    a.resize(n);
    const double T = end_time_ - start_time_;
    if (T <= 0.0 || time > end_time_) {
      // No window yet, or past its end: uniform motion at the end velocity.
      const double dt = T <= 0.0 ? 0.0 : time - end_time_;
      for (std::size_t k = 0; k < n; ++k)
        for (int d = 0; d < D; ++d) {
          x[k][d] = x1_[k][d] + dt * v1_[k][d];
          v[k][d] = v1_[k][d];
          a[k][d] = 0.0;
        }
    } else {
      // Cubic Hermite basis in s = (t - t0) / T and its first two derivatives.
      const double s = (time - start_time_) / T, s2 = s * s, s3 = s2 * s;
      const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
      const double d00 = 6 * s2 - 6 * s, d10 = 3 * s2 - 4 * s + 1, d01 = -d00, d11 = 3 * s2 - 2 * s;
      const double e00 = 12 * s - 6, e10 = 6 * s - 4, e01 = -e00, e11 = 6 * s - 2;
      for (std::size_t k = 0; k < n; ++k)
        for (int d = 0; d < D; ++d) {
          const double p0 = x0_[k][d], m0 = T * v0_[k][d], p1 = x1_[k][d], m1 = T * v1_[k][d];
          x[k][d] = h00 * p0 + h10 * m0 + h01 * p1 + h11 * m1;
          v[k][d] = (d00 * p0 + d10 * m0 + d01 * p1 + d11 * m1) / T;
          a[k][d] = (e00 * p0 + e10 * m0 + e01 * p1 + e11 * m1) / (T * T);
        }
    }
    current_time_ = time;
    x_ = x;
    v_ = v;
  }

  // Restart state: the window's times and all node states (names under `prefix`).
  void save(RestartWriter& out, const std::string& prefix) const {
    out.scalars(prefix + ".times", std::vector<double>{start_time_, end_time_, current_time_});
    out.vectors(prefix + ".x0", x0_);
    out.vectors(prefix + ".v0", v0_);
    out.vectors(prefix + ".x1", x1_);
    out.vectors(prefix + ".v1", v1_);
    out.vectors(prefix + ".x", x_);
    out.vectors(prefix + ".v", v_);
  }
  void load(const RestartReader& in, const std::string& prefix) {
    const auto times = in.scalars<double>(prefix + ".times", 3);
    const std::size_t n = x_.size();
    x0_ = in.vectors<D>(prefix + ".x0", n);
    v0_ = in.vectors<D>(prefix + ".v0", n);
    x1_ = in.vectors<D>(prefix + ".x1", n);
    v1_ = in.vectors<D>(prefix + ".v1", n);
    x_ = in.vectors<D>(prefix + ".x", n);
    v_ = in.vectors<D>(prefix + ".v", n);
    start_time_ = times[0];
    end_time_ = times[1];
    current_time_ = times[2];
  }

  double current_time() const { return current_time_; }
  double start_time() const { return start_time_; }
  double end_time() const { return end_time_; }
  // Largest node speed at the start and the end of the window.
  double max_end_speed() const {
    double v2 = 0.0;
    for (const auto* vs : {&v0_, &v1_})
      for (const auto& v : *vs) {
        double s = 0.0;
        for (int d = 0; d < D; ++d) s += v[d] * v[d];
        v2 = std::max(v2, s);
      }
    return std::sqrt(v2);
  }

 private:
  double start_time_, end_time_, current_time_;
  std::vector<V> x0_, v0_, x1_, v1_;
  // The state at the current time (a new window starts from it).
  std::vector<V> x_, v_;
};

}  // namespace valvefsi::fluid::thin_wall
