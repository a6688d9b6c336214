#include "valvefsi/fluid/thin_wall/thin_wall_flow_2d.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>

#include "valvefsi/fluid/equation_of_state.hpp"
#include "valvefsi/fluid/interactions.hpp"
#include "valvefsi/fluid/kernels.hpp"
#include "valvefsi/fluid/pair_loop.hpp"

namespace valvefsi::fluid::thin_wall {

ThinWallFlow2D::ThinWallFlow2D(ThinWallCase2D c)
    : settings_(c.fluid),
      particles_(fill_particles<2>(c.scene, c.fluid)),
      grid_(c.fluid.domain_lower, c.fluid.domain_upper, c.fluid.support_radius(), c.fluid.periodic),
      wall_(std::move(c.wall), c.fluid, c.wall_settings),
      motion_(std::move(c.motion)) {
  if (motion_) motion_(0.0, wall_.wall());
  lost_ = grid_.wrap_and_mark_lost(particles_);
  grid_.sort(particles_);
  wall_.classify(particles_);
  evaluate_rates();
  choose_time_step();
}

void ThinWallFlow2D::evaluate_rates() {
  update_fluid_pressure<2>(particles_, settings_);
  wall_.update_marker_states(particles_, grid_);
  update_tank_state();
  compute_fluid_rates();
  wall_.add_wall_rates(particles_);
}

// Adami et al. 2012 (eq. 27) for the tank's dummy particles, from fluid on their side only.
void ThinWallFlow2D::update_tank_state() {
  auto& p = particles_;
  const auto& s = settings_;
  const LinearMieGruneisen eos{s.rest_density, s.sound_speed};
  with_kernel<2>(s.kernel, s.smoothing_length(), [&](const auto& W) {
    for_each_particle_with_neighbours<2>(grid_, [&](std::uint32_t w, const auto& segments, int count) {
      if (p.kind[w] != Kind::wall) return;
      double sum_w = 0, sum_p = 0, sum_rho_r[2] = {0, 0}, sum_v[2] = {0, 0};
      for (int k = 0; k < count; ++k) {
        const auto& seg = segments[k];
        for (std::uint32_t b = seg.begin; b < seg.end; ++b) {
          if (p.kind[b] != Kind::fluid) continue;
          const double dx = p.position[0][w] - (p.position[0][b] + seg.shift[0]);
          const double dy = p.position[1][w] - (p.position[1][b] + seg.shift[1]);
          const double wk = W.value(static_cast<float>(std::sqrt(dx * dx + dy * dy)));
          if (wk <= 0 || wall_.blocked(w, b, p)) continue;
          const double rho_b = s.rest_density + p.density_excess[b];
          sum_w += wk;
          sum_p += p.pressure[b] * wk;
          sum_rho_r[0] += rho_b * dx * wk;
          sum_rho_r[1] += rho_b * dy * wk;
          sum_v[0] += p.velocity[0][b] * wk;
          sum_v[1] += p.velocity[1][b] * wk;
        }
      }
      if (sum_w > 0) {
        const double pw = (sum_p + s.gravity[0] * sum_rho_r[0] + s.gravity[1] * sum_rho_r[1]) / sum_w;
        const double excess = eos.density_excess(pw - s.background_pressure);
        p.pressure[w] = static_cast<float>(pw);
        p.density_excess[w] = static_cast<float>(excess);
        p.inverse_density[w] = static_cast<float>(1.0 / (s.rest_density + excess));
        for (int d = 0; d < 2; ++d) p.viscous_velocity[d][w] = static_cast<float>(2.0 * p.velocity[d][w] - sum_v[d] / sum_w);
      } else {
        p.pressure[w] = static_cast<float>(s.background_pressure);
        p.density_excess[w] = 0.0f;
        p.inverse_density[w] = static_cast<float>(1.0 / s.rest_density);
        for (int d = 0; d < 2; ++d) p.viscous_velocity[d][w] = p.velocity[d][w];
      }
    });
  });
}

// The library's fluid rates (continuity with delta-SPH, pressure, laminar and artificial
// viscosity, kernel sum) with blocked pairs left out; the tank's reaction is summed on the way.
void ThinWallFlow2D::compute_fluid_rates() {
  auto& p = particles_;
  const auto& s = settings_;
  const double m = s.particle_mass();
  const double h = s.smoothing_length();
  const double two_mu = 2.0 * s.dynamic_viscosity;
  const double alpha_c0 = s.artificial_viscosity * s.sound_speed;
  const double eta2 = 0.01 * h * h;
  const double diffusion = 2.0 * s.density_diffusion * h * s.sound_speed;
  const double hydrostatic = s.rest_density / (s.sound_speed * s.sound_speed);
  p.kernel_sum.resize(p.size());
  for (int d = 0; d < 2; ++d) p.kernel_sum_gradient[d].resize(p.size());
  const int threads = omp_get_max_threads();
  std::vector<Vec2> tank(static_cast<std::size_t>(threads), Vec2{0.0, 0.0});
  with_kernel<2>(s.kernel, h, [&](const auto& W) {
    for_each_particle_with_neighbours<2>(grid_, [&](std::uint32_t a, const auto& segments, int count) {
      if (p.kind[a] != Kind::fluid) return;
      const double inv_a = p.inverse_density[a];
      const double p_a = p.pressure[a];
      const double ex_a = p.density_excess[a];
      double acc[2] = {0, 0}, cont = 0, diff = 0, csum = 0, cg[2] = {0, 0}, on_tank[2] = {0, 0};
      for (int k = 0; k < count; ++k) {
        const auto& seg = segments[k];
        for (std::uint32_t b = seg.begin; b < seg.end; ++b) {
          const double dx = p.position[0][a] - (p.position[0][b] + seg.shift[0]);
          const double dy = p.position[1][a] - (p.position[1][b] + seg.shift[1]);
          const double r2 = dx * dx + dy * dy;
          const double r = std::sqrt(r2);
          if (r >= s.support_radius() || wall_.blocked(a, b, p)) continue;
          const double F = W.gradient_factor(static_cast<float>(r));
          const double inv_b = p.inverse_density[b];
          const double inv_rr = inv_a * inv_b;
          const double vdx = (p.velocity[0][a] - p.velocity[0][b]) * dx + (p.velocity[1][a] - p.velocity[1][b]) * dy;
          double radial = -(p_a + p.pressure[b]) * inv_rr;
          if (alpha_c0 > 0) radial += alpha_c0 * h * std::min(vdx, 0.0) / (r2 + eta2) * 0.5 * (inv_a + inv_b);
          radial *= F;
          const double viscous = two_mu * inv_rr * F;
          const double ax = radial * dx + viscous * (p.viscous_velocity[0][a] - p.viscous_velocity[0][b]);
          const double ay = radial * dy + viscous * (p.viscous_velocity[1][a] - p.viscous_velocity[1][b]);
          acc[0] += ax;
          acc[1] += ay;
          cont += vdx * F;
          if (p.kind[b] == Kind::fluid) {
            const double g_dot_rba = -(s.gravity[0] * dx + s.gravity[1] * dy);
            diff += (p.density_excess[b] - ex_a - hydrostatic * g_dot_rba) * (-F) * inv_b;
          } else {
            on_tank[0] -= ax;
            on_tank[1] -= ay;
          }
          csum += W.value(static_cast<float>(r)) * inv_b;
          cg[0] += F * dx * inv_b;
          cg[1] += F * dy * inv_b;
        }
      }
      for (int d = 0; d < 2; ++d) p.acceleration[d][a] = static_cast<float>(m * acc[d] + s.gravity[d]);
      p.density_rate[a] = static_cast<float>(m * (cont + diffusion * diff));
      p.kernel_sum[a] = static_cast<float>(m * csum);
      for (int d = 0; d < 2; ++d) p.kernel_sum_gradient[d][a] = static_cast<float>(m * cg[d]);
      Vec2& t = tank[static_cast<std::size_t>(omp_get_thread_num())];
      t[0] += m * m * on_tank[0];
      t[1] += m * m * on_tank[1];
    });
  });
  tank_force_ = {0.0, 0.0};
  for (const auto& t : tank) {
    tank_force_[0] += t[0];
    tank_force_[1] += t[1];
  }
}

void ThinWallFlow2D::step() {
  const double dt = dt_;
  auto& p = particles_;
  const auto n = static_cast<std::ptrdiff_t>(p.size());
  wall_.begin_step(p);
  // First kick and drift, as FluidSolver::step.
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    if (p.kind[i] != Kind::fluid) continue;
    for (int d = 0; d < 2; ++d) {
      p.velocity[d][i] += static_cast<float>(0.5 * dt) * p.acceleration[d][i];
      p.viscous_velocity[d][i] = p.velocity[d][i];
      p.position[d][i] += dt * static_cast<double>(p.velocity[d][i]);
    }
    p.density_excess[i] += static_cast<float>(dt) * p.density_rate[i];
    p.density_rate_previous[i] = p.density_rate[i];
  }
  time_ += dt;
  if (motion_) motion_(time_, wall_.wall());
  wall_.correct_crossings(p);

  lost_ += grid_.wrap_and_mark_lost(p);
  grid_.sort(p);
  wall_.classify(p);
  evaluate_rates();

  double max_v2 = 0, max_a2 = 0;
#pragma omp parallel for schedule(static) reduction(max : max_v2, max_a2)
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    if (p.kind[i] != Kind::fluid) continue;
    double v2 = 0, a2 = 0;
    for (int d = 0; d < 2; ++d) {
      p.velocity[d][i] += static_cast<float>(0.5 * dt) * p.acceleration[d][i];
      v2 += static_cast<double>(p.velocity[d][i]) * p.velocity[d][i];
      a2 += static_cast<double>(p.acceleration[d][i]) * p.acceleration[d][i];
    }
    p.density_excess[i] += static_cast<float>(0.5 * dt) * (p.density_rate[i] - p.density_rate_previous[i]);
    max_v2 = std::max(max_v2, v2);
    max_a2 = std::max(max_a2, a2);
  }
  max_speed_ = std::sqrt(max_v2);
  max_acceleration_ = std::sqrt(max_a2);
  if (settings_.shifting > 0) shift_particles(dt);
  ++steps_;
  choose_time_step();
}

// FluidSolver's shifting, with every shift that would cross or touch the wall rejected.
void ThinWallFlow2D::shift_particles(double dt) {
  auto& p = particles_;
  const auto& s = settings_;
  const double scale = s.shifting * s.smoothing_length() * max_speed_ * dt;
  const double cap = s.max_shift_fraction * s.particle_spacing;
  const auto n = static_cast<std::ptrdiff_t>(p.size());
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t ii = 0; ii < n; ++ii) {
    const auto i = static_cast<std::size_t>(ii);
    if (p.kind[i] != Kind::fluid || p.kernel_sum[i] < s.free_surface_kernel_sum) continue;
    Vec2 shift{-scale * p.kernel_sum_gradient[0][i], -scale * p.kernel_sum_gradient[1][i]};
    const double length = std::sqrt(shift[0] * shift[0] + shift[1] * shift[1]);
    if (length > cap) shift = {shift[0] * cap / length, shift[1] * cap / length};
    if (!wall_.accept_shift(p, i, shift)) continue;
    p.position[0][i] += shift[0];
    p.position[1][i] += shift[1];
  }
}

void ThinWallFlow2D::choose_time_step() {
  const auto& s = settings_;
  const double h = s.smoothing_length();
  double dt = s.cfl * h / (s.sound_speed + max_speed_);
  if (max_acceleration_ > 0) dt = std::min(dt, s.cfl * std::sqrt(h / max_acceleration_));
  if (s.dynamic_viscosity > 0) dt = std::min(dt, 0.125 * h * h * s.rest_density / s.dynamic_viscosity);
  dt_ = std::min(dt, s.max_time_step);
}

void ThinWallFlow2D::advance_to(double end_time) {
  while (time_ < end_time * (1.0 - 1e-12)) {
    if (time_ + dt_ > end_time) dt_ = end_time - time_;
    step();
  }
}

}  // namespace valvefsi::fluid::thin_wall
