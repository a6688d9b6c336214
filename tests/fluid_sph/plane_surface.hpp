#pragma once
// A test double of an immersed surface: the fixed plane x = x0 (a line in 2D) that separates
// the particles on its two sides. Particles that cross it in a step are put back (to their x
// at the step's start, normal velocity removed) and counted (or, with put_back = false, left
// where they are and counted as leaks). With `mirror`, each side also
// sees the mirror images of its own near-plane particles (pressure and continuity terms), a
// minimal wall condition so that the fluid rests against the plane instead of piling into it.
#include <atomic>
#include <cmath>
#include <vector>

#include "valvefsi/fluid/fluid_settings.hpp"
#include "valvefsi/fluid/immersed_surface.hpp"
#include "valvefsi/fluid/kernels.hpp"

namespace valvefsi::fluid::testing {

template <int D>
class PlaneSurface final : public ImmersedSurfaceModel<D> {
 public:
  // block = false: flags the same near particles but blocks no pair (the filtered path must
  // then give exactly the unfiltered answer).
  PlaneSurface(double x0, double near_distance, bool block = true, const FluidSettings<D>* mirror = nullptr)
      : x0_(x0), near_(near_distance), block_(block), mirror_(mirror ? *mirror : FluidSettings<D>{}), with_mirror_(mirror != nullptr) {}

  void set_window_target(double, std::span<const Vec<D>>, std::span<const Vec<D>>) override {}
  void move_to(double) override {}
  double max_node_speed() const override { return 0.0; }

  void begin_step(const Particles<D>& p) override {
    side_.resize(p.size());
    start_x_.resize(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
      side_[i] = p.position[0][i] < x0_;
      start_x_[i] = p.position[0][i];
    }
  }
  void correct_crossings(Particles<D>& p) override {
    if (!block_) return;
    for (std::size_t i = 0; i < p.size() && i < side_.size(); ++i) {
      if (p.kind[i] != Kind::fluid || (p.position[0][i] < x0_) == side_[i]) continue;
      if (!put_back) {  // a model that misses the crossing: the particle leaked
        ++counters_.leaks;
        continue;
      }
      p.position[0][i] = start_x_[i];  // back to where the step began, stopped along x
      p.velocity[0][i] = 0.0f;
      ++counters_.corrections;
    }
  }
  void classify(const Particles<D>& p) override {
    near_flags_.resize(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) near_flags_[i] = std::abs(p.position[0][i] - x0_) < near_;
    ++classify_calls;
  }
  bool near_surface(std::size_t i) const override { return near_flags_[i] != 0; }
  bool blocked(std::uint32_t a, std::uint32_t b, const Particles<D>& p) const override {
    blocked_calls.fetch_add(1, std::memory_order_relaxed);
    return block_ && ((p.position[0][a] < x0_) != (p.position[0][b] < x0_));
  }
  void update_surface_states(const Particles<D>&, const CellGrid<D>&) override {}
  void add_surface_rates(Particles<D>& p) override {
    if (!with_mirror_) return;
    std::vector<std::size_t> near;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (near_flags_[i] && p.kind[i] == Kind::fluid) near.push_back(i);
    const float mass = static_cast<float>(mirror_.particle_mass());
    const double support2 = mirror_.support_radius() * mirror_.support_radius();
    with_kernel<D>(mirror_.kernel, mirror_.smoothing_length(), [&](const auto& W) {
      for (std::size_t a : near) {
        for (std::size_t b : near) {
          if ((p.position[0][a] < x0_) != (p.position[0][b] < x0_)) continue;
          // Ghost of b: x mirrored about the plane, normal velocity reversed.
          double r[D];
          double r2 = 0;
          for (int d = 0; d < D; ++d) {
            const double xb = d == 0 ? 2.0 * x0_ - p.position[0][b] : p.position[d][b];
            r[d] = p.position[d][a] - xb;
            r2 += r[d] * r[d];
          }
          if (r2 >= support2) continue;
          const float F = W.gradient_factor(static_cast<float>(std::sqrt(r2)));
          const float radial = -(p.pressure[a] + p.pressure[b]) * p.inverse_density[a] * p.inverse_density[b] * F;
          float vdx = 0;
          for (int d = 0; d < D; ++d) {
            const float vb = d == 0 ? -p.velocity[0][b] : p.velocity[d][b];
            vdx += (p.velocity[d][a] - vb) * static_cast<float>(r[d]);
            p.acceleration[d][a] += mass * radial * static_cast<float>(r[d]);
          }
          p.density_rate[a] += mass * vdx * F;
        }
      }
    });
  }
  bool accept_shift(const Particles<D>& p, std::size_t i, const Vec<D>& shift) override {
    const bool ok = !block_ || ((p.position[0][i] < x0_) == (p.position[0][i] + shift[0] < x0_));
    if (!ok) ++counters_.rejected_shifts;
    ++accept_shift_calls;
    return ok;
  }
  std::size_t node_count() const override { return 1; }
  void node_forces(std::span<Vec<D>> forces) const override { forces[0] = Vec<D>{}; }
  ImmersedSurfaceCounters counters() const override { return counters_; }
  void save_checkpoint() override {}
  void restore_checkpoint() override {}

  // false: crossings are not put back but counted as leaks (a model that lost track).
  bool put_back = true;
  long classify_calls = 0;
  long accept_shift_calls = 0;
  mutable std::atomic<long> blocked_calls{0};  // the pair loops call blocked() from threads

 private:
  double x0_, near_;
  bool block_;
  FluidSettings<D> mirror_;
  bool with_mirror_;
  std::vector<char> side_;
  std::vector<double> start_x_;
  std::vector<char> near_flags_;
  ImmersedSurfaceCounters counters_;
};

}  // namespace valvefsi::fluid::testing
