#include "valvefsi/fluid/thin_wall/two_sided_wall.hpp"

#include <fmt/format.h>
#include <omp.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "valvefsi/fluid/equation_of_state.hpp"
#include "valvefsi/fluid/kernels.hpp"

namespace valvefsi::fluid::thin_wall {
namespace {

double dot(const Vec2& a, const Vec2& b) { return a[0] * b[0] + a[1] * b[1]; }

Vec2 position_of(const Particles<2>& p, std::size_t i) { return {p.position[0][i], p.position[1][i]}; }

// Cell of a point in the grid's numbering (x fastest), clamped into the grid.
std::size_t cell_of_point(const CellGrid<2>& grid, const Vec2& x) {
  std::size_t c = 0;
  for (int d = 1; d >= 0; --d) {
    int k = static_cast<int>(std::floor((x[d] - grid.lower()[d]) / grid.cell_size(d)));
    k = std::clamp(k, 0, grid.cells_along(d) - 1);
    c = c * static_cast<std::size_t>(grid.cells_along(d)) + static_cast<std::size_t>(k);
  }
  return c;
}

}  // namespace

TwoSidedWall::TwoSidedWall(Polyline wall, const FluidSettings<2>& fluid, ThinWallSettings settings)
    : wall_(std::move(wall)), markers_(wall_, fluid.particle_spacing), fluid_(fluid), settings_(settings) {}

void TwoSidedWall::classify(const Particles<2>& p) {
  const std::size_t n = p.size();
  near_.assign(n, NearWall{});
  candidates_.resize(n);
  std::uint32_t max_id = 0;
  for (std::size_t i = 0; i < n; ++i) max_id = std::max(max_id, p.id[i]);
  if (side_by_id_.size() <= max_id) side_by_id_.resize(max_id + 1, 0);
  if (corrected_by_id_.size() <= max_id) corrected_by_id_.resize(max_id + 1, 0);

  wall_box_ = {wall_.position[0][0], wall_.position[0][1], wall_.position[0][0], wall_.position[0][1]};
  for (const auto& x : wall_.position) {
    wall_box_[0] = std::min(wall_box_[0], x[0]);
    wall_box_[1] = std::min(wall_box_[1], x[1]);
    wall_box_[2] = std::max(wall_box_[2], x[0]);
    wall_box_[3] = std::max(wall_box_[3], x[1]);
  }
  const double R = fluid_.support_radius();
  std::size_t leaks = 0;
  const auto count = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel for schedule(dynamic, 256) reduction(+ : leaks)
  for (std::ptrdiff_t ii = 0; ii < count; ++ii) {
    const auto i = static_cast<std::size_t>(ii);
    candidates_[i].clear();
    const std::uint32_t id = p.id[i];
    if (p.kind[i] == Kind::lost) continue;
    const Vec2 x = position_of(p, i);
    if (x[0] < wall_box_[0] - R || x[0] > wall_box_[2] + R || x[1] < wall_box_[1] - R || x[1] > wall_box_[3] + R) {
      if (p.kind[i] == Kind::fluid) side_by_id_[id] = 0;
      continue;
    }
    segments_near(wall_, x, R, candidates_[i]);
    if (candidates_[i].empty()) {
      if (p.kind[i] == Kind::fluid) side_by_id_[id] = 0;
      continue;
    }
    NearWall& nw = near_[i];
    nw.closest = closest_point(wall_, candidates_[i], x);
    nw.near = true;
    if (p.kind[i] != Kind::fluid) continue;
    // A particle may change side only around a free end or through a put-back; otherwise it
    // leaked (entering the near zone from outside cannot be a crossing).
    auto& remembered = side_by_id_[id];
    const auto side = static_cast<std::int8_t>(nw.closest.side);
    // A straight step from the last position that misses the wall went round a free end
    // (the side test alone would call that a leak when the end of the step is no longer
    // beyond the tip).
    if (remembered != 0 && remembered != side && !nw.closest.at_free_end && !corrected_by_id_[id] &&
        (id >= previous_by_id_.size() || crosses(wall_, previous_by_id_[id], x))) {
      ++leaks;
#pragma omp critical(thin_wall_leak_log)
      log_leak(id, remembered, x, nw.closest);
    }
    remembered = side;
  }
  counters_.leaks += leaks;
}

void TwoSidedWall::log_leak(std::uint32_t id, int remembered, const Vec2& x, const ClosestPoint& c) const {
  // A leak is rare and stops the run soon: say where and how it crossed, so that the cause can
  // be found (docs/fsi-2d.md, session 7: the leak near the folding root).
  const Vec2 x0 = id < previous_by_id_.size() ? previous_by_id_[id] : x;
  const auto straight = first_crossing(wall_, x0, x);
  std::string swept = "no begin_step";
  if (start_nodes_.size() == wall_.position.size()) {
    const auto s = swept_crossing(start_nodes_, wall_.position, x0, x);
    swept = s ? fmt::format("odd, first on segment {} at tau {:.3f}", s->segment, s->tau) : "even (0 or 2 events)";
  }
  // The bend at the crossed segment's ends: the angle between neighbouring segments' tangents.
  const std::size_t k = straight ? straight->segment : c.segment;
  auto bend = [&](std::size_t a) {
    if (a == 0 || a >= wall_.segment_count()) return 0.0;
    const Vec2 t0 = wall_.tangent(a - 1), t1 = wall_.tangent(a);
    return std::atan2(t0[0] * t1[1] - t0[1] * t1[0], dot(t0, t1)) * 180.0 / 3.141592653589793;
  };
  const Vec2 moved = start_nodes_.size() == wall_.position.size()
                         ? Vec2{wall_.position[k][0] - start_nodes_[k][0], wall_.position[k][1] - start_nodes_[k][1]}
                         : Vec2{0.0, 0.0};
  // A leaflet that passes through itself (the solid has no self-contact) has no consistent sides.
  std::string self = "none";
  double nearest = 1e300;
  for (std::size_t i = 0; i + 2 < wall_.segment_count(); ++i)
    for (std::size_t j = i + 2; j < wall_.segment_count(); ++j) {
      const auto hit = first_crossing(wall_, std::vector<std::uint32_t>{static_cast<std::uint32_t>(j)}, wall_.position[i],
                                      wall_.position[i + 1]);
      if (!hit) continue;
      const Vec2 q = wall_.point(j, hit->t);
      const double d = std::hypot(q[0] - x[0], q[1] - x[1]);
      if (d < nearest) {
        nearest = d;
        self = fmt::format("segments {} and {} cross at ({:.4f}, {:.4f}) mm, {:.4f} mm from the particle", i, j, 1e3 * q[0],
                           1e3 * q[1], 1e3 * d);
      }
    }
  spdlog::warn(
      "thin wall: leak of particle id {} from side {} to {}: step ({:.4f}, {:.4f}) -> ({:.4f}, {:.4f}) mm crosses the end wall's "
      "segment {} (straight test {}), swept test {}; closest segment {} t {:.3f} at {:.4f} mm; bends at the segment's ends "
      "{:.1f} / {:.1f} deg; its start node moved ({:.4f}, {:.4f}) mm in the step; {} segments; self-crossing of the wall: {}",
      id, remembered, c.side, 1e3 * x0[0], 1e3 * x0[1], 1e3 * x[0], 1e3 * x[1], k, straight ? "yes" : "no", swept, c.segment, c.t,
      1e3 * c.distance, bend(k), bend(k + 1), 1e3 * moved[0], 1e3 * moved[1], wall_.segment_count(), self);
}

bool TwoSidedWall::blocked(std::uint32_t a, std::uint32_t b, const Particles<2>& p) const {
  if (!near_[a].near || !near_[b].near) return false;
  return first_crossing(wall_, candidates_[a], position_of(p, a), position_of(p, b)).has_value();
}

void TwoSidedWall::update_marker_states(const Particles<2>& p, const CellGrid<2>& grid) {
  const double R = fluid_.support_radius();
  const double tiny = 1e-6 * fluid_.particle_spacing;
  const auto count = static_cast<std::ptrdiff_t>(markers_.size());
  with_kernel<2>(fluid_.kernel, fluid_.smoothing_length(), [&](const auto& W) {
#pragma omp parallel for schedule(dynamic, 8)
    for (std::ptrdiff_t mm = 0; mm < count; ++mm) {
      Marker& m = markers_[static_cast<std::size_t>(mm)];
      const Vec2 xm = wall_.point(m.segment, m.t);
      const Vec2 nm = wall_.normal(m.segment);
      const Vec2 am = settings_.wall_acceleration_in_pressure ? wall_.acceleration_at(m.segment, m.t) : Vec2{0.0, 0.0};
      std::array<NeighbourSegment<2>, 9> segments;
      const int segment_count = grid.neighbour_segments(cell_of_point(grid, xm), segments);
      double sw[2] = {0, 0}, sp[2] = {0, 0}, srr[2][2] = {{0, 0}, {0, 0}}, sv[2][2] = {{0, 0}, {0, 0}};
      for (int s = 0; s < segment_count; ++s) {
        const auto& seg = segments[s];
        for (std::uint32_t b = seg.begin; b < seg.end; ++b) {
          if (p.kind[b] != Kind::fluid || !near_[b].near) continue;
          const Vec2 xb{p.position[0][b] + seg.shift[0], p.position[1][b] + seg.shift[1]};
          const Vec2 r{xm[0] - xb[0], xm[1] - xb[1]};
          const double dist = std::sqrt(dot(r, r));
          if (dist >= R) continue;
          const int side = near_[b].closest.side;
          // The marker as seen from b's side: nothing of the wall may lie in between.
          const Vec2 target{xm[0] + side * tiny * nm[0], xm[1] + side * tiny * nm[1]};
          if (first_crossing(wall_, candidates_[b], xb, target)) continue;
          const double w = W.value(static_cast<float>(dist));
          const int k = side_index(side);
          const double rho_b = fluid_.rest_density + p.density_excess[b];
          sw[k] += w;
          sp[k] += p.pressure[b] * w;
          for (int d = 0; d < 2; ++d) {
            srr[k][d] += rho_b * r[d] * w;
            sv[k][d] += p.velocity[d][b] * w;
          }
        }
      }
      for (int k = 0; k < 2; ++k) {
        SideState& st = m.side[k];
        st.weight = sw[k];
        if (sw[k] > 0) {
          // Adami, Hu & Adams 2012, eq. 27, with the wall's acceleration (if enabled).
          double pw = sp[k];
          for (int d = 0; d < 2; ++d) pw += (fluid_.gravity[d] - am[d]) * srr[k][d];
          st.pressure = pw / sw[k];
          st.extrapolated_velocity = {sv[k][0] / sw[k], sv[k][1] / sw[k]};
        } else {
          st.pressure = fluid_.background_pressure;
          st.extrapolated_velocity = wall_.velocity_at(m.segment, m.t);
        }
      }
    }
  });
}

void TwoSidedWall::add_wall_rates(Particles<2>& p) {
  const double dp = fluid_.particle_spacing;
  const double R = fluid_.support_radius();
  const double delta = settings_.virtual_spacing_ratio * dp;
  const int layers = static_cast<int>(std::ceil(R / delta));
  const double rho0 = fluid_.rest_density;
  const double mass_a = fluid_.particle_mass();
  const double mass_v = rho0 * delta * delta;
  const double two_mu = 2.0 * fluid_.dynamic_viscosity;
  const double alpha_c0 = fluid_.artificial_viscosity * fluid_.sound_speed;
  const double h = fluid_.smoothing_length();
  const double eta2 = 0.01 * h * h;
  const LinearMieGruneisen eos{rho0, fluid_.sound_speed};
  const bool with_kernel_sum = p.kernel_sum.size() == p.size();
  virtual_kernel_sum_.assign(p.size(), 0.0f);

  marker_loads_.reset(markers_.size(), p.size());
  const auto blocks = static_cast<std::ptrdiff_t>(marker_loads_.block_count());
  with_kernel<2>(fluid_.kernel, h, [&](const auto& W) {
#pragma omp parallel
    {
      OrderedNodeLoads<2>::Booking forces(marker_loads_);
      // The markers' loads are booked per block of particles and summed in block order
      // (OrderedNodeLoads): the same in every run, on any number of threads.
#pragma omp for schedule(dynamic, 4)
      for (std::ptrdiff_t block = 0; block < blocks; ++block) {
        const auto [first, last] = marker_loads_.block_range(static_cast<std::size_t>(block));
        for (std::size_t a = first; a < last; ++a) {
          if (p.kind[a] != Kind::fluid || !near_[a].near) continue;
          const ClosestPoint& c = near_[a].closest;
          const Vec2 xa = position_of(p, a);
          // Lattice axes: n from the closest point towards the particle (rotates smoothly around
          // a free end), t along the wall.
          Vec2 n{xa[0] - c.point[0], xa[1] - c.point[1]};
          const double nl = std::sqrt(dot(n, n));
          if (nl > 1e-9 * dp) {
            n = {n[0] / nl, n[1] / nl};
          } else {
            n = wall_.normal(c.segment);
            n = {c.side * n[0], c.side * n[1]};
          }
          const Vec2 t{-n[1], n[0]};
          const int k_side = side_index(c.side);
          const double rho_a = rho0 + p.density_excess[a];
          const double inv_a = 1.0 / rho_a;
          const double p_a = p.pressure[a];
          const Vec2 va{p.velocity[0][a], p.velocity[1][a]};
          const Vec2 vva{p.viscous_velocity[0][a], p.viscous_velocity[1][a]};
          double acc[2] = {0, 0}, cont = 0, csum = 0, cg[2] = {0, 0}, wsum = 0;
          for (int j = 1; j <= layers; ++j) {
            const double depth = (j - 0.5) * delta;
            for (int i = -layers; i <= layers; ++i) {
              const Vec2 xv{c.point[0] + i * delta * t[0] - depth * n[0],
                            c.point[1] + i * delta * t[1] - depth * n[1]};
              const Vec2 r{xa[0] - xv[0], xa[1] - xv[1]};
              const double r2 = dot(r, r);
              if (r2 >= R * R) continue;
              std::size_t seg;
              double tw;
              // Beyond a free end the lattice's middle column lies on the ray from the particle
              // through the end node: it only grazes the tip and stands for the fluid beyond it,
              // so it is left out. Asked of first_crossing, the answer depended on round-off and
              // the loads jumped by % when the motion changed by an ulp (issue 8: the coupler's
              // implicit iterations could not converge).
              if (settings_.shadow_only && c.at_free_end && i == 0) continue;
              if (settings_.shadow_only) {
                const auto hit = first_crossing(wall_, candidates_[a], xa, xv);
                if (!hit) continue;
                seg = hit->segment;
                tw = hit->t;
              } else {
                const ClosestPoint cv = closest_point(wall_, candidates_[a], xv);
                seg = cv.segment;
                tw = cv.t;
              }
              // That side's wall state at the wall point q where the particle sees the virtual
              // point, extrapolated hydrostatically (with the wall's acceleration) to it.
              const Vec2 q = wall_.point(seg, tw);
              const MarkerWeights mw = markers_.weights_at(markers_.arc_length(seg, tw));
              int k_state = k_side;
              bool beyond = false;
              if (settings_.opposite_state_beyond_edge || settings_.fluid_velocity_beyond_edge) {
                const Vec2 e{wall_.position[seg + 1][0] - wall_.position[seg][0],
                             wall_.position[seg + 1][1] - wall_.position[seg][1]};
                const double along = ((xv[0] - wall_.position[seg][0]) * e[0] +
                                      (xv[1] - wall_.position[seg][1]) * e[1]) /
                                     dot(e, e);
                beyond =
                    (seg == 0 && along < 0.0) || (seg + 1 == wall_.segment_count() && along > 1.0);
                if (beyond && settings_.opposite_state_beyond_edge) k_state = 1 - k_side;
              }
              bool round_edge = false;
              if (settings_.other_side_round_edge || settings_.fluid_velocity_round_edge) {
                for (const Vec2& e : {wall_.position.front(), wall_.position.back()})
                  round_edge = round_edge || std::hypot(xa[0] - e[0], xa[1] - e[1]) +
                                                     std::hypot(xv[0] - e[0], xv[1] - e[1]) <
                                                 R;
                if (round_edge && settings_.other_side_round_edge) k_state = 1 - k_side;
              }
              // The virtual point stands for moving fluid, not for the wall.
              const bool fluid_like = (beyond && settings_.fluid_velocity_beyond_edge) ||
                                      (round_edge && settings_.fluid_velocity_round_edge);
              const SideState& s0 = markers_[mw.first].side[k_state];
              const SideState& s1 = markers_[mw.second].side[k_state];
              Vec2 vw = wall_.velocity_at(seg, tw);
              if (fluid_like)
                for (int d = 0; d < 2; ++d)
                  vw[d] = mw.w0 * s0.extrapolated_velocity[d] + mw.w1 * s1.extrapolated_velocity[d];
              const Vec2 aw = settings_.wall_acceleration_in_pressure
                                  ? wall_.acceleration_at(seg, tw)
                                  : Vec2{0.0, 0.0};
              double p_v = mw.w0 * s0.pressure + mw.w1 * s1.pressure;
              for (int d = 0; d < 2; ++d)
                p_v += rho0 * (fluid_.gravity[d] - aw[d]) * (xv[d] - q[d]);
              Vec2 vv_v;
              for (int d = 0; d < 2; ++d)
                vv_v[d] = fluid_like ? vw[d]
                                     : 2.0 * vw[d] - (mw.w0 * s0.extrapolated_velocity[d] +
                                                      mw.w1 * s1.extrapolated_velocity[d]);
              const double inv_v =
                  1.0 / (rho0 + eos.density_excess(p_v - fluid_.background_pressure));
              const double dist = std::sqrt(r2);
              const double F = W.gradient_factor(static_cast<float>(dist));
              const double wv = W.value(static_cast<float>(dist));
              const double inv_rr = inv_a * inv_v;
              const double vdx = (va[0] - vw[0]) * r[0] + (va[1] - vw[1]) * r[1];
              double radial = -(p_a + p_v) * inv_rr;
              if (alpha_c0 > 0)
                radial += alpha_c0 * h * std::min(vdx, 0.0) / (r2 + eta2) * 0.5 * (inv_a + inv_v);
              radial *= F;
              const double viscous = two_mu * inv_rr * F;
              double da[2];
              for (int d = 0; d < 2; ++d)
                da[d] = mass_v * (radial * r[d] + viscous * (vva[d] - vv_v[d]));
              acc[0] += da[0];
              acc[1] += da[1];
              if (settings_.normal_only_continuity && !fluid_like) {
                // Only the wall's normal motion compresses the fluid: tangential slip along the
                // wall does not (a truncated lattice near a free end would not cancel it).
                const Vec2 nq = wall_.normal(seg);
                const double vn = (va[0] - vw[0]) * nq[0] + (va[1] - vw[1]) * nq[1];
                cont += mass_v * vn * (nq[0] * r[0] + nq[1] * r[1]) * F;
              } else {
                cont += mass_v * vdx * F;
              }
              csum += mass_v * wv * inv_v;
              cg[0] += mass_v * F * r[0] * inv_v;
              cg[1] += mass_v * F * r[1] * inv_v;
              wsum += wv * delta * delta;
              // Action = reaction: the opposite force goes to the markers that carried the state,
              // from the gauge pressure p - p_b: the background pressure is an offset of the
              // equation of state, and where only one side of a leaflet is wetted (against a
              // rigid wall, at a closed tip) it would push the leaflet (57 N/m on the 2D valve at
              // rest). Where both sides are wetted the two offsets cancel anyway.
              const double gauge = 2.0 * fluid_.background_pressure * inv_rr * F * mass_v;
              for (int d = 0; d < 2; ++d) {
                const double load = mass_a * (da[d] + gauge * r[d]);
                forces.at(mw.first)[d] -= mw.w0 * load;
                forces.at(mw.second)[d] -= mw.w1 * load;
              }
            }
          }
          for (int d = 0; d < 2; ++d) p.acceleration[d][a] += static_cast<float>(acc[d]);
          p.density_rate[a] += static_cast<float>(cont);
          if (with_kernel_sum) {
            p.kernel_sum[a] += static_cast<float>(csum);
            for (int d = 0; d < 2; ++d) p.kernel_sum_gradient[d][a] += static_cast<float>(cg[d]);
          }
          virtual_kernel_sum_[a] = static_cast<float>(wsum);
        }
        forces.close_block(static_cast<std::size_t>(block));
      }
    }
  });
  marker_loads_.sum_into(marker_force_);
  for (std::size_t m = 0; m < markers_.size(); ++m) markers_[m].force = marker_force_[m];
}

void TwoSidedWall::begin_step(const Particles<2>& p) {
  start_position_.resize(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) start_position_[i] = position_of(p, i);
  start_nodes_ = wall_.position;
  std::uint32_t max_id = 0;
  for (std::size_t i = 0; i < p.size(); ++i) max_id = std::max(max_id, p.id[i]);
  previous_by_id_.resize(static_cast<std::size_t>(max_id) + 1);
  for (std::size_t i = 0; i < p.size(); ++i) previous_by_id_[p.id[i]] = start_position_[i];
  std::fill(corrected_by_id_.begin(), corrected_by_id_.end(), std::uint8_t{0});
}

void TwoSidedWall::correct_crossings(Particles<2>& p) {
  const double R = fluid_.support_radius();
  const double clearance = settings_.clearance_ratio * fluid_.particle_spacing;
  if (start_nodes_.size() != wall_.position.size() || start_position_.size() != p.size()) return;  // no begin_step yet
  // The box swept by the wall over the step (classify's box is the last step's).
  std::array<double, 4> box{start_nodes_[0][0], start_nodes_[0][1], start_nodes_[0][0], start_nodes_[0][1]};
  for (const auto* nodes : {&start_nodes_, &wall_.position})
    for (const auto& x : *nodes) {
      box = {std::min(box[0], x[0]), std::min(box[1], x[1]), std::max(box[2], x[0]), std::max(box[3], x[1])};
    }
  std::size_t corrections = 0;
  const auto count = static_cast<std::ptrdiff_t>(p.size());
#pragma omp parallel for schedule(dynamic, 256) reduction(+ : corrections)
  for (std::ptrdiff_t ii = 0; ii < count; ++ii) {
    const auto i = static_cast<std::size_t>(ii);
    if (p.kind[i] != Kind::fluid) continue;
    const Vec2 x0 = start_position_[i];
    Vec2 x1 = position_of(p, i);
    if (x0[0] < box[0] - R || x0[0] > box[2] + R || x0[1] < box[1] - R || x0[1] > box[3] + R) continue;
    const auto hit = swept_crossing(start_nodes_, wall_.position, x0, x1);
    if (!hit) continue;
    const std::size_t k = hit->segment;
    // Side at the start of the step, from the segment that was crossed.
    const Vec2 a0 = start_nodes_[k], b0 = start_nodes_[k + 1];
    const double c0 = (b0[0] - a0[0]) * (x0[1] - a0[1]) - (b0[1] - a0[1]) * (x0[0] - a0[0]);
    const double side = c0 >= 0.0 ? 1.0 : -1.0;
    const Vec2 nk = wall_.normal(k);
    const Vec2 n{side * nk[0], side * nk[1]};
    const Vec2 a1 = wall_.position[k];
    const double signed_distance = (x1[0] - a1[0]) * n[0] + (x1[1] - a1[1]) * n[1];
    const double depth = std::max(-signed_distance, 0.0);
    const double move = depth + std::max(depth, clearance);
    for (int d = 0; d < 2; ++d) p.position[d][i] = x1[d] + move * n[d];
    // Reflect the velocity relative to the wall, normal part only, if it points into the wall.
    const Vec2 vw = wall_.velocity_at(k, hit->t);
    const double vn = (p.velocity[0][i] - vw[0]) * n[0] + (p.velocity[1][i] - vw[1]) * n[1];
    if (vn < 0.0) {
      for (int d = 0; d < 2; ++d) {
        p.velocity[d][i] = static_cast<float>(p.velocity[d][i] - 2.0 * vn * n[d]);
        p.viscous_velocity[d][i] = p.velocity[d][i];
      }
    }
    if (p.id[i] < corrected_by_id_.size()) corrected_by_id_[p.id[i]] = 1;
    ++corrections;
  }
  counters_.corrections += corrections;
}

bool TwoSidedWall::accept_shift(const Particles<2>& p, std::size_t i, const Vec2& shift) {
  const Vec2 x = position_of(p, i);
  if (i < near_.size() && !near_[i].near) return true;
  const Vec2 y{x[0] + shift[0], x[1] + shift[1]};
  bool ok = !crosses(wall_, x, y);
  if (ok) {
    const double clearance = settings_.clearance_ratio * fluid_.particle_spacing;
    const double after = closest_point(wall_, y).distance;
    ok = !(after < clearance && after < closest_point(wall_, x).distance);
  }
  if (!ok) {
#pragma omp atomic
    ++counters_.rejected_shifts;
  }
  return ok;
}

void TwoSidedWall::save_state(RestartWriter& out, const std::string& prefix) const {
  out.vectors(prefix + ".nodes.x", wall_.position);
  out.vectors(prefix + ".nodes.v", wall_.velocity);
  out.vectors(prefix + ".nodes.a", wall_.acceleration);
  out.vectors(prefix + ".nodes.start_position", start_nodes_);
  std::vector<std::array<double, 10>> markers(markers_.size());
  for (std::size_t m = 0; m < markers_.size(); ++m) {
    const Marker& mk = markers_[m];
    for (std::size_t k = 0; k < 2; ++k) {
      markers[m][4 * k] = mk.side[k].pressure;
      markers[m][4 * k + 1] = mk.side[k].extrapolated_velocity[0];
      markers[m][4 * k + 2] = mk.side[k].extrapolated_velocity[1];
      markers[m][4 * k + 3] = mk.side[k].weight;
    }
    markers[m][8] = mk.force[0];
    markers[m][9] = mk.force[1];
  }
  out.vectors(prefix + ".markers", markers);
  out.scalars(prefix + ".counters", std::vector<double>{static_cast<double>(counters_.corrections), static_cast<double>(counters_.leaks),
                                                         static_cast<double>(counters_.rejected_shifts)});
  std::vector<std::array<double, 8>> near(near_.size());
  for (std::size_t i = 0; i < near_.size(); ++i) {
    const ClosestPoint& c = near_[i].closest;
    near[i] = {near_[i].near ? 1.0 : 0.0, static_cast<double>(c.segment), c.t, c.point[0], c.point[1], c.distance,
               static_cast<double>(c.side), c.at_free_end ? 1.0 : 0.0};
  }
  out.vectors(prefix + ".particles.near", near);
  out.lists(prefix + ".particles.candidates", candidates_);
  out.vectors(prefix + ".particles.start_position", start_position_);
  out.scalars(prefix + ".particles.virtual_kernel_sum", virtual_kernel_sum_);
  out.scalars(prefix + ".by_id.side", side_by_id_);
  out.scalars(prefix + ".by_id.corrected", corrected_by_id_);
  out.vectors(prefix + ".by_id.previous_position", previous_by_id_);
  out.scalars(prefix + ".box", std::vector<double>(wall_box_.begin(), wall_box_.end()));
}

void TwoSidedWall::load_state(const RestartReader& in, const std::string& prefix) {
  const std::size_t nodes = wall_.node_count();
  auto position = in.vectors<2>(prefix + ".nodes.x", nodes);
  auto velocity = in.vectors<2>(prefix + ".nodes.v", nodes);
  auto acceleration = in.vectors<2>(prefix + ".nodes.a", nodes);
  auto start_nodes = in.vectors<2>(prefix + ".nodes.start_position");
  if (!start_nodes.empty() && start_nodes.size() != nodes)
    throw std::runtime_error(fmt::format("{}: array '{}.nodes.start_position' has {} nodes: allowed 0 or {}", in.owner(), prefix,
                                         start_nodes.size(), nodes));
  const auto markers = in.vectors<10>(prefix + ".markers", markers_.size());
  const auto counters = in.scalars<std::size_t>(prefix + ".counters", 3);
  const auto near = in.vectors<8>(prefix + ".particles.near");
  auto candidates = in.lists(prefix + ".particles.candidates", near.size());
  for (const auto& list : candidates)
    for (const auto k : list)
      if (k >= wall_.segment_count())
        throw std::runtime_error(fmt::format("{}: array '{}.particles.candidates.values' names segment {}: allowed 0 to {}", in.owner(),
                                             prefix, k, wall_.segment_count() - 1));
  std::vector<NearWall> near_walls(near.size());
  for (std::size_t i = 0; i < near.size(); ++i) {
    const auto& e = near[i];
    if (e[1] < 0 || e[1] >= static_cast<double>(wall_.segment_count()))
      throw std::runtime_error(fmt::format("{}: array '{}.particles.near' names segment {} for particle {}: allowed 0 to {}", in.owner(),
                                           prefix, e[1], i, wall_.segment_count() - 1));
    near_walls[i].near = e[0] != 0.0;
    ClosestPoint& c = near_walls[i].closest;
    c.segment = static_cast<std::size_t>(e[1]);
    c.t = e[2];
    c.point = {e[3], e[4]};
    c.distance = e[5];
    c.side = static_cast<int>(e[6]);
    c.at_free_end = e[7] != 0.0;
  }
  auto start_position = in.vectors<2>(prefix + ".particles.start_position");
  auto kernel_sum = in.scalars<float>(prefix + ".particles.virtual_kernel_sum");
  auto side_by_id = in.scalars<std::int8_t>(prefix + ".by_id.side");
  auto corrected_by_id = in.scalars<std::uint8_t>(prefix + ".by_id.corrected");
  auto previous_by_id = in.vectors<2>(prefix + ".by_id.previous_position");
  const auto box = in.scalars<double>(prefix + ".box", 4);

  wall_.position = std::move(position);
  wall_.velocity = std::move(velocity);
  wall_.acceleration = std::move(acceleration);
  start_nodes_ = std::move(start_nodes);
  for (std::size_t m = 0; m < markers_.size(); ++m) {
    Marker& mk = markers_[m];
    for (std::size_t k = 0; k < 2; ++k) {
      mk.side[k].pressure = markers[m][4 * k];
      mk.side[k].extrapolated_velocity = {markers[m][4 * k + 1], markers[m][4 * k + 2]};
      mk.side[k].weight = markers[m][4 * k + 3];
    }
    mk.force = {markers[m][8], markers[m][9]};
  }
  counters_ = {counters[0], counters[1], counters[2]};
  near_ = std::move(near_walls);
  candidates_ = std::move(candidates);
  start_position_ = std::move(start_position);
  virtual_kernel_sum_ = std::move(kernel_sum);
  side_by_id_ = std::move(side_by_id);
  corrected_by_id_ = std::move(corrected_by_id);
  previous_by_id_ = std::move(previous_by_id);
  wall_box_ = {box[0], box[1], box[2], box[3]};
}

}  // namespace valvefsi::fluid::thin_wall
