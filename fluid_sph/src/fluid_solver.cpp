#include "valvefsi/fluid/fluid_solver.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>

#include "valvefsi/fluid/interactions.hpp"

namespace valvefsi::fluid {
namespace {

template <int D>
void check_settings(const FluidSettings<D>& s) {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("fluid settings: " + what);
  };
  require(s.particle_spacing > 0, "particle_spacing = " + std::to_string(s.particle_spacing) + ": allowed > 0");
  require(s.smoothing_length_ratio >= 0.5 && s.smoothing_length_ratio <= 4,
          "smoothing_length_ratio = " + std::to_string(s.smoothing_length_ratio) + ": allowed 0.5 .. 4");
  require(s.rest_density > 0, "rest_density = " + std::to_string(s.rest_density) + ": allowed > 0");
  require(s.sound_speed > 0, "sound_speed = " + std::to_string(s.sound_speed) + ": allowed > 0");
  require(s.dynamic_viscosity >= 0, "dynamic_viscosity = " + std::to_string(s.dynamic_viscosity) + ": allowed >= 0");
  require(s.cfl > 0 && s.cfl <= 1, "cfl = " + std::to_string(s.cfl) + ": allowed in (0, 1]");
}

}  // namespace

template <int D>
struct FluidSolver<D>::Checkpoint {
  // Everything a step reads, as it was: the particles in their order (with their rates and
  // scratch), the grid whose cell ranges match that order, and the near-surface flags. Nothing
  // is re-sorted or re-evaluated on restore, so a repeated window is bit-for-bit the first.
  Particles<D> particles;
  std::optional<CellGrid<D>> grid;
  std::vector<std::uint8_t> near_surface;
  std::vector<PressurePlate<D>> plates;
  std::vector<Vec<D>> body_forces, body_acceleration;
  double time = 0.0, dt = 0.0;
  long steps = 0;
  std::size_t lost = 0, lost_density = 0, named_losses = 0;
  bool plate_floor_reached = true;
  float max_speed = 0.0f, max_acceleration = 0.0f;
  std::size_t owned_begin = 0, owned_end = 0;
};

template <int D>
FluidSolver<D>::FluidSolver(const FluidSettings<D>& settings, Particles<D> particles, std::vector<PressurePlate<D>> plates,
                            std::unique_ptr<ImmersedSurfaceModel<D>> surface)
    : settings_((check_settings(settings), settings)),
      particles_(std::move(particles)),
      plates_(std::move(plates)),
      grid_(settings.domain_lower, settings.domain_upper, settings.support_radius(), settings.periodic),
      body_forces_(plates_.size() + 1, Vec<D>{}),
      body_acceleration_(plates_.size() + 1, Vec<D>{}),
      surface_(std::move(surface)) {
  for (std::size_t i = 0; i < particles_.size(); ++i)
    if (particles_.body[i] > plates_.size())
      throw std::invalid_argument("fluid particles: body index " + std::to_string(particles_.body[i]) +
                                  " has no pressure plate (plates: " + std::to_string(plates_.size()) + ")");
  for (const auto& plane : settings_.mirror_planes) {
    double length2 = 0;
    for (int d = 0; d < D; ++d) length2 += plane.normal[d] * plane.normal[d];
    if (std::abs(length2 - 1.0) > 1e-9)
      throw std::invalid_argument("fluid settings: a mirror plane's normal has length " + std::to_string(std::sqrt(length2)) +
                                  ": allowed 1 (normalise it)");
  }
  if (settings_.mirror_images_of_images) {
    try {
      compound_mirror_maps_ = compound_mirror_maps<D>(settings_.mirror_planes);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("fluid settings: mirror_planes: ") + e.what());
    }
  }
  plate_floor_reached_ = !settings_.plate_floor_once_reached;
  note_plate_floor(time_);
  refresh_mirror_images();
  initial_fluid_count_ = particles_.count(Kind::fluid);
  leak_limit_ = static_cast<std::size_t>(std::floor(settings_.max_leak_fraction * static_cast<double>(initial_fluid_count_)));
  lost_ = grid_.wrap_and_mark_lost(particles_);
  grid_.sort(particles_);
  update_owned_range();
  if (surface_) classify_surface();
  evaluate_rates();
  choose_time_step();
}

template <int D>
void FluidSolver<D>::update_owned_range() {
  if (slabs_) {
    std::tie(owned_begin_, owned_end_) = slabs_->owned_range(grid_);
  } else {
    owned_begin_ = 0;
    owned_end_ = particles_.size();
  }
}

template <int D>
void FluidSolver<D>::decompose(MPI_Comm comm) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  if (size == 1) return;
  if (steps_ != 0) throw std::logic_error("FluidSolver::decompose: call it before the first step");
  if (surface_)
    throw std::invalid_argument("fluid MPI decomposition: immersed surfaces (leaflets) run on one rank only; "
                                "run fluid_sph without mpirun (or -np 1) for this case");
  constexpr int axis = SlabDecomposition<D>::kAxis;
  for (const auto& plane : settings_.mirror_planes)
    if (std::abs(plane.normal[axis]) > 1e-12)
      throw std::invalid_argument(fmt::format("fluid MPI decomposition: a mirror plane's normal has a component {} along "
                                              "the slab axis {}; allowed 0 (planes containing the axis, like a sector's) "
                                              "or run on one rank", plane.normal[axis], axis));
  if (settings_.shifting > 0 && settings_.shifting_density == FluidSettings<D>::ShiftingDensity::continuity)
    throw std::invalid_argument("fluid MPI decomposition: shifting_density_correction SHIFT_CONTINUITY reads the neighbours' "
                                "shifts, which are not exchanged across slab borders; run on one rank or use "
                                "FIELD_AT_NEW_POSITION");
  slabs_ = std::make_unique<SlabDecomposition<D>>(comm, grid_, particles_);
  slabs_->keep_own_and_halo(particles_);
  add_mirror_images();
  grid_.sort(particles_);
  update_owned_range();
  evaluate_rates();
  max_speed_ = max_acceleration_ = 0.0f;
  choose_time_step();
}

template <int D>
void FluidSolver<D>::refresh_mirror_images() {
  drop_mirror_images_and_reflect();
  add_mirror_images();
}

template <int D>
void FluidSolver<D>::drop_mirror_images_and_reflect() {
  if (settings_.mirror_planes.empty()) return;
  auto& p = particles_;
  // Drop last step's images (compacting every array); add_mirror_images makes new ones.
  // One tight loop per array (the images are spread over the cells after the sort, so nearly
  // every particle moves): the arrays are compacted in parallel, each in place in order.
  mirror_keep_.clear();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (!is_mirror(p.kind[i])) mirror_keep_.push_back(static_cast<std::uint32_t>(i));
  const std::size_t kept = mirror_keep_.size();
  std::vector<std::function<void()>> compactions;
  p.for_each_array([&](auto& a) {
    compactions.emplace_back([&a, this, kept]() {
      for (std::size_t j = 0; j < kept; ++j) a[j] = a[mirror_keep_[j]];
      a.resize(kept);
    });
  });
#pragma omp parallel for schedule(dynamic, 1)
  for (std::size_t c = 0; c < compactions.size(); ++c) compactions[c]();
  // A fluid particle that stepped across a plane swaps roles with its image, which stepped
  // the other way: reflect it back (position and normal velocity), as a specular wall would.
  for (const auto& plane : settings_.mirror_planes) {
    for (std::size_t i = 0; i < kept; ++i) {
      if (p.kind[i] != Kind::fluid) continue;
      double distance = 0, normal_speed = 0;
      for (int d = 0; d < D; ++d) {
        distance += (p.position[d][i] - plane.point[d]) * plane.normal[d];
        normal_speed += p.velocity[d][i] * plane.normal[d];
      }
      if (distance >= 0) continue;
      for (int d = 0; d < D; ++d) {
        p.position[d][i] -= 2.0 * distance * plane.normal[d];
        p.velocity[d][i] = static_cast<float>(p.velocity[d][i] - 2.0 * normal_speed * plane.normal[d]);
        p.viscous_velocity[d][i] = p.velocity[d][i];
      }
    }
  }
}

template <int D>
void FluidSolver<D>::add_mirror_images() {
  if (settings_.mirror_planes.empty()) return;
  auto& p = particles_;
  // Mirror every fluid and wall particle within a support of a plane: x' = x - 2 d n,
  // v' = v - 2 (v.n) n.
  const std::size_t kept = p.size();
  const double support = settings_.support_radius();
  const auto& lower = settings_.domain_lower;
  const auto& upper = settings_.domain_upper;
  for (const auto& plane : settings_.mirror_planes) {
    for (std::size_t i = 0; i < kept; ++i) {
      const Kind k = p.kind[i];
      if (k != Kind::fluid && k != Kind::wall) continue;
      double distance = 0, normal_speed = 0;
      for (int d = 0; d < D; ++d) {
        distance += (p.position[d][i] - plane.point[d]) * plane.normal[d];
        normal_speed += p.velocity[d][i] * plane.normal[d];
      }
      if (distance < 0 || distance >= support) continue;
      Vec<D> x{};
      std::array<float, D> v{};
      bool inside = true;
      for (int d = 0; d < D; ++d) {
        x[d] = p.position[d][i] - 2.0 * distance * plane.normal[d];
        v[d] = static_cast<float>(p.velocity[d][i] - 2.0 * normal_speed * plane.normal[d]);
        inside = inside && (settings_.periodic[d] || (x[d] >= lower[d] && x[d] < upper[d]));
      }
      if (!inside) continue;  // outside the domain: no neighbour of anything inside it
      p.add(x, v, p.density_excess[i], k == Kind::fluid ? Kind::mirror_fluid : Kind::mirror_wall, p.body[i]);
    }
  }
  // Images of images (rotations and the other reflections of the planes' group): only those
  // within a support of every plane's fluid side can be a neighbour of a fluid particle.
  for (const auto& map : compound_mirror_maps_) {
    for (std::size_t i = 0; i < kept; ++i) {
      const Kind k = p.kind[i];
      if (k != Kind::fluid && k != Kind::wall) continue;
      Vec<D> x0, v0;
      for (int d = 0; d < D; ++d) {
        x0[d] = p.position[d][i];
        v0[d] = p.velocity[d][i];
      }
      const Vec<D> x = map.apply(x0);
      bool near = true;
      for (const auto& plane : settings_.mirror_planes) {
        double distance = 0;
        for (int d = 0; d < D; ++d) distance += (x[d] - plane.point[d]) * plane.normal[d];
        near = near && distance > -support;
      }
      for (int d = 0; d < D && near; ++d) near = settings_.periodic[d] || (x[d] >= lower[d] && x[d] < upper[d]);
      if (!near) continue;
      const Vec<D> u = map.rotate(v0);
      std::array<float, D> v{};
      for (int d = 0; d < D; ++d) v[d] = static_cast<float>(u[d]);
      p.add(x, v, p.density_excess[i], k == Kind::fluid ? Kind::mirror_fluid : Kind::mirror_wall, p.body[i]);
    }
  }
}

template <int D>
void FluidSolver<D>::set_immersed_surface(std::unique_ptr<ImmersedSurfaceModel<D>> surface) {
  surface_ = std::move(surface);
  near_surface_.clear();
  surface_force_sum_.clear();
  surface_force_time_ = 0.0;
  if (surface_) classify_surface();
  evaluate_rates();
  if (steps_ == 0) choose_time_step();
}

template <int D>
void FluidSolver<D>::classify_surface() {
  surface_->classify(particles_);
  near_surface_.resize(particles_.size());
  const auto n = static_cast<std::ptrdiff_t>(particles_.size());
  const ImmersedSurfaceModel<D>& model = *surface_;
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t i = 0; i < n; ++i)
    near_surface_[static_cast<std::size_t>(i)] = model.near_surface(static_cast<std::size_t>(i)) ? 1 : 0;
}

template <int D>
PairFilter<D> FluidSolver<D>::pair_filter() const {
  if (!surface_) return {};
  return PairFilter<D>{surface_.get(), &particles_, near_surface_.data()};
}

template <int D>
void FluidSolver<D>::reset_surface_force_average() {
  surface_force_sum_.assign(surface_ ? surface_->node_count() : 0, Vec<D>{});
  surface_force_time_ = 0.0;
}

template <int D>
std::vector<Vec<D>> FluidSolver<D>::surface_force_average() const {
  if (!surface_) return {};
  std::vector<Vec<D>> average(surface_->node_count(), Vec<D>{});
  if (surface_force_time_ > 0 && surface_force_sum_.size() == average.size()) {
    for (std::size_t j = 0; j < average.size(); ++j)
      for (int d = 0; d < D; ++d) average[j][d] = surface_force_sum_[j][d] / surface_force_time_;
  } else {
    surface_->node_forces(average);  // no step taken yet: the forces of the current state
  }
  return average;
}

template <int D>
void FluidSolver<D>::save_checkpoint() {
  if (!checkpoint_) checkpoint_ = std::make_shared<Checkpoint>();
  auto& c = *checkpoint_;
  c.particles = particles_;
  c.grid = grid_;
  c.near_surface = near_surface_;
  c.plates = plates_;
  c.body_forces = body_forces_;
  c.body_acceleration = body_acceleration_;
  c.time = time_;
  c.dt = dt_;
  c.steps = steps_;
  c.lost = lost_;
  c.lost_density = lost_density_;
  c.named_losses = named_losses_.size();
  c.plate_floor_reached = plate_floor_reached_;
  c.max_speed = max_speed_;
  c.max_acceleration = max_acceleration_;
  c.owned_begin = owned_begin_;
  c.owned_end = owned_end_;
  if (surface_) surface_->save_checkpoint();
}

template <int D>
void FluidSolver<D>::restore_checkpoint() {
  if (!checkpoint_) throw std::logic_error("FluidSolver::restore_checkpoint: no checkpoint was saved");
  const auto& c = *checkpoint_;
  particles_ = c.particles;
  grid_ = *c.grid;
  near_surface_ = c.near_surface;
  plates_ = c.plates;
  body_forces_ = c.body_forces;
  body_acceleration_ = c.body_acceleration;
  time_ = c.time;
  dt_ = c.dt;
  steps_ = c.steps;
  lost_ = c.lost;
  lost_density_ = c.lost_density;
  named_losses_.resize(c.named_losses);  // a repeated window names its losses again
  plate_floor_reached_ = c.plate_floor_reached;
  max_speed_ = c.max_speed;
  max_acceleration_ = c.max_acceleration;
  owned_begin_ = c.owned_begin;
  owned_end_ = c.owned_end;
  if (surface_) surface_->restore_checkpoint();
}

template <int D>
void FluidSolver<D>::evaluate_rates() {
  const PairFilter<D> filter = pair_filter();
  update_fluid_pressure<D>(particles_, settings_);
  if (surface_) surface_->update_surface_states(particles_, grid_);
  for (std::size_t k = 0; k < plates_.size(); ++k)
    for (int d = 0; d < D; ++d) body_acceleration_[k + 1][d] = plates_[k].acceleration * plates_[k].normal[d];
  update_wall_state<D>(particles_, grid_, settings_, body_acceleration_, filter);
  if (!plates_.empty() || body_forces_requested_ || body_forces_always_) {
    body_forces_.assign(plates_.size() + 1, Vec<D>{});
    compute_fluid_rates<D>(particles_, grid_, settings_, filter, &body_forces_, body_forces_requested_ || body_forces_always_,
                           owned_begin_, owned_end_);
    body_forces_requested_ = false;
    // Each rank booked the reactions of its own fluid: the bodies feel the sum.
    if (slabs_) slabs_->sum(std::span<double>(body_forces_.front().data(), body_forces_.size() * D));
  } else {
    compute_fluid_rates<D>(particles_, grid_, settings_, filter, nullptr, false, owned_begin_, owned_end_);
  }
  if (surface_) surface_->add_surface_rates(particles_);
}

template <int D>
void FluidSolver<D>::step() {
  const double dt = dt_;
  const float half = static_cast<float>(0.5 * dt);
  const float full = static_cast<float>(dt);
  auto& p = particles_;
  // Split over ranks, only the own particles are integrated (the halo is replaced after the drift).
  auto first = static_cast<std::ptrdiff_t>(owned_begin_), last = static_cast<std::ptrdiff_t>(owned_end_);
  if (surface_) surface_->begin_step(p);

  // Only the fluid moves and nothing else moves it before the wrap (no plates, images, surface
  // or slabs): each particle is wrapped or marked lost right after its drift, in the same pass.
  const bool wrap_in_drift = plates_.empty() && settings_.mirror_planes.empty() && !surface_ && !slabs_;
  std::size_t lost_in_drift = 0;

  // First kick (velocity half step, density predicted to the full step) and drift (eq. 4).
#pragma omp parallel for schedule(static) reduction(+ : lost_in_drift)
  for (std::ptrdiff_t i = first; i < last; ++i) {
    if (p.kind[i] != Kind::fluid) continue;
    for (int d = 0; d < D; ++d) {
      p.velocity[d][i] += half * p.acceleration[d][i];
      p.viscous_velocity[d][i] = p.velocity[d][i];
      p.position[d][i] += dt * static_cast<double>(p.velocity[d][i]);
    }
    p.density_excess[i] += full * p.density_rate[i];
    p.density_rate_previous[i] = p.density_rate[i];
    if (wrap_in_drift && grid_.wrap_or_mark_lost(p, static_cast<std::size_t>(i))) ++lost_in_drift;
  }
  for (auto& plate : plates_) {
    plate.velocity += 0.5 * dt * plate.acceleration;
    plate.displacement += dt * plate.velocity;
  }
  if (!plates_.empty()) {
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t i = first; i < last; ++i) {
      if (p.kind[i] != Kind::wall || p.body[i] == 0) continue;
      const auto& plate = plates_[p.body[i] - 1];
      for (int d = 0; d < D; ++d) {
        p.position[d][i] += dt * plate.velocity * plate.normal[d];
        p.velocity[d][i] = static_cast<float>(plate.velocity * plate.normal[d]);
      }
    }
  }
  time_ += dt;
  note_plate_floor(time_);
  if (surface_) {
    surface_->move_to(time_);
    surface_->correct_crossings(p);
  }
  if (slabs_) {
    // Own particles only, then migration to the neighbours and their fresh halo copies; the
    // images are made from both.
    slabs_->drop_halo(p, owned_begin_, owned_end_);
    drop_mirror_images_and_reflect();
    const double newly_lost = static_cast<double>(grid_.wrap_and_mark_lost(p));
    slabs_->migrate_and_share_halo(p);
    add_mirror_images();
    lost_ += static_cast<std::size_t>(slabs_->sum(newly_lost));
  } else if (wrap_in_drift) {
    lost_ += lost_in_drift;
  } else {
    refresh_mirror_images();
    lost_ += grid_.wrap_and_mark_lost(p);
  }
  grid_.sort(p);
  update_owned_range();  // the mirror images and the exchange changed the count
  first = static_cast<std::ptrdiff_t>(owned_begin_);
  last = static_cast<std::ptrdiff_t>(owned_end_);
  if (surface_) classify_surface();
  evaluate_rates();
  if (surface_) {
    // Window average of the surface loads: each step's forces weighted by its length.
    surface_force_scratch_.resize(surface_->node_count());
    surface_->node_forces(surface_force_scratch_);
    if (surface_force_sum_.size() != surface_force_scratch_.size()) reset_surface_force_average();
    for (std::size_t j = 0; j < surface_force_scratch_.size(); ++j)
      for (int d = 0; d < D; ++d) surface_force_sum_[j][d] += dt * surface_force_scratch_[j][d];
    surface_force_time_ += dt;
  }

  const double plate_level = settings_.background_pressure + plate_pressure_level(time_);
  for (std::size_t k = 0; k < plates_.size(); ++k) {
    auto& plate = plates_[k];
    plate.fluid_force = body_forces_[k + 1];
    plate.acceleration = plate.acceleration_at(time_, plate.fluid_force, plate_level);
    plate.velocity += 0.5 * dt * plate.acceleration;
  }

  // Second kick: velocity to the full step, density corrected to the trapezoidal rule.
  float max_speed2 = 0.0f, max_acc2 = 0.0f;
  const float density_limit = static_cast<float>(settings_.max_density_deviation * settings_.rest_density);
  std::size_t out_of_range = 0;
  std::vector<std::size_t> taken_out;  // rare: each is logged below
#pragma omp parallel for schedule(static) reduction(max : max_speed2, max_acc2) reduction(+ : out_of_range)
  for (std::ptrdiff_t i = first; i < last; ++i) {
    if (p.kind[i] != Kind::fluid) continue;
    // Like DualSPHysics' RhopOut: a particle whose density leaves the band (a splash droplet
    // expanding without neighbours) is taken out rather than allowed to blow up the step.
    if (std::abs(p.density_excess[i]) > density_limit) {
      p.kind[i] = Kind::lost;
      ++out_of_range;
#pragma omp critical(valvefsi_fluid_taken_out)
      taken_out.push_back(static_cast<std::size_t>(i));
      continue;
    }
    float v2 = 0.0f, a2 = 0.0f;
    for (int d = 0; d < D; ++d) {
      p.velocity[d][i] += half * p.acceleration[d][i];
      v2 += p.velocity[d][i] * p.velocity[d][i];
      a2 += p.acceleration[d][i] * p.acceleration[d][i];
    }
    p.density_excess[i] += half * (p.density_rate[i] - p.density_rate_previous[i]);
    max_speed2 = std::max(max_speed2, v2);
    max_acc2 = std::max(max_acc2, a2);
  }
  if (slabs_) {
    max_speed2 = static_cast<float>(slabs_->max(max_speed2));
    max_acc2 = static_cast<float>(slabs_->max(max_acc2));
    out_of_range = static_cast<std::size_t>(slabs_->sum(static_cast<double>(out_of_range)));
  }
  max_speed_ = std::sqrt(max_speed2);
  max_acceleration_ = std::sqrt(max_acc2);
  lost_ += out_of_range;
  lost_density_ += out_of_range;
  std::sort(taken_out.begin(), taken_out.end());  // the threads' order is not the particles'
  for (const std::size_t i : taken_out) {
    if (named_losses_.size() >= kNamedLosses) break;
    TakenOut t;
    t.id = p.id[i];
    t.time = time_;
    t.step = steps_ + 1;
    for (int d = 0; d < D; ++d) {
      t.position[d] = p.position[d][i];
      t.speed += static_cast<double>(p.velocity[d][i]) * p.velocity[d][i];
    }
    t.speed = std::sqrt(t.speed);
    t.density = settings_.rest_density + p.density_excess[i];
    t.near_surface = i < near_surface_.size() && near_surface_[i];
    named_losses_.push_back(t);
  }
  if (settings_.shifting > 0) shift_particles(dt);
  ++steps_;
  if (surface_) check_leaks();  // the state is complete: it can be written
  check_plate_travel();
  choose_time_step();
}

template <int D>
double FluidSolver<D>::lowest_plate_drive(double t) const {
  double lowest = std::numeric_limits<double>::infinity();
  for (const auto& plate : plates_) lowest = std::min(lowest, plate.pressure(t));
  return settings_.background_pressure + lowest;
}

template <int D>
double FluidSolver<D>::plate_pressure_level(double t) const {
  if (!settings_.plates_never_pull || plates_.empty()) return 0.0;
  // Before a once-reached floor is reached the plates only never pull. At the step that
  // reaches it the lowest drive is at or above the floor, so the level is 0 either way and
  // it does not jump when the floor engages.
  const double floor = plate_floor_reached_ ? settings_.plate_pressure_floor : 0.0;
  return std::max(0.0, floor - lowest_plate_drive(t));
}

template <int D>
void FluidSolver<D>::note_plate_floor(double t) {
  if (plate_floor_reached_ || !settings_.plates_never_pull || plates_.empty()) return;
  if (lowest_plate_drive(t) >= settings_.plate_pressure_floor) plate_floor_reached_ = true;
}

template <int D>
void FluidSolver<D>::shift_particles(double dt) {
  auto& p = particles_;
  const auto& s = settings_;
  const double scale_per_speed = s.shifting * s.smoothing_length() * dt;
  using Speed = typename FluidSettings<D>::ShiftingSpeed;
  const double cap = s.max_shift_fraction * s.particle_spacing;
  const auto first = static_cast<std::ptrdiff_t>(owned_begin_), n = static_cast<std::ptrdiff_t>(owned_end_);
  const bool with_surface = surface_ != nullptr && near_surface_.size() == p.size();
  // Which particles shift at their own speed: none, all, or those away from an immersed surface.
  const bool own_speed_far = s.shifting_speed != Speed::fastest_particle;
  const bool own_speed_near = s.shifting_speed == Speed::own_speed;
  // near: within a support of an immersed surface.
  auto shift_of = [&](std::ptrdiff_t i, bool near) {
    const bool own_speed = near ? own_speed_near : own_speed_far;
    double speed2 = 0;
    if (own_speed)
      for (int d = 0; d < D; ++d) speed2 += static_cast<double>(p.velocity[d][i]) * p.velocity[d][i];
    const double scale = scale_per_speed * (own_speed ? std::sqrt(speed2) : static_cast<double>(max_speed_));
    Vec<D> shift{};
    double length2 = 0;
    for (int d = 0; d < D; ++d) {
      shift[d] = -scale * p.kernel_sum_gradient[d][i];
      length2 += shift[d] * shift[d];
    }
    const double factor = length2 > cap * cap ? cap / std::sqrt(length2) : 1.0;
    for (int d = 0; d < D; ++d) shift[d] *= factor;
    return shift;
  };
  // Every shift is decided before any particle moves: the density correction reads the
  // neighbours' shifts at the old positions. 0 for particles that do not move.
  for (int d = 0; d < D; ++d) shift_.at(d).assign(p.size(), 0.0);
  auto eligible = [&](std::ptrdiff_t i) { return p.kind[i] == Kind::fluid && p.kernel_sum[i] >= s.free_surface_kernel_sum; };
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t i = first; i < n; ++i) {
    if (!eligible(i) || (with_surface && near_surface_[static_cast<std::size_t>(i)])) continue;  // near: asked below
    const Vec<D> shift = shift_of(i, false);
    for (int d = 0; d < D; ++d) shift_[d][i] = shift[d];
  }
  if (with_surface) {
    // Near the surface the model decides (a shift must not carry a particle across it); the
    // model keeps counters, so these calls stay on one thread.
    for (std::ptrdiff_t i = first; i < n; ++i) {
      if (!near_surface_[static_cast<std::size_t>(i)] || !eligible(i)) continue;
      const Vec<D> shift = shift_of(i, true);
      if (!surface_->accept_shift(p, static_cast<std::size_t>(i), shift)) continue;
      for (int d = 0; d < D; ++d) shift_[d][i] = shift[d];
    }
  }
  const bool correct = s.shifting_density != FluidSettings<D>::ShiftingDensity::keep;
  if (correct) {
    const PairFilter<D> filter = pair_filter();
    shifting_density_change<D>(p, grid_, s, filter, shift_, shift_density_change_, owned_begin_, owned_end_);
    if (s.shifting_density == FluidSettings<D>::ShiftingDensity::continuity)
      smooth_shifting_density_change<D>(p, grid_, s, filter, shift_density_change_, shift_density_scratch_, owned_begin_, owned_end_);
  }
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t i = first; i < n; ++i) {
    for (int d = 0; d < D; ++d) p.position[d][i] += shift_[d][i];
    if (correct) p.density_excess[i] += shift_density_change_[i];
  }
}

template <int D>
void FluidSolver<D>::choose_time_step() {
  const auto& s = settings_;
  const double h = s.smoothing_length();
  if (steps_ == 0) {
    float a2 = 0.0f;
    for (std::size_t i = owned_begin_; i < owned_end_; ++i) {
      if (particles_.kind[i] != Kind::fluid) continue;
      float v2 = 0.0f, acc2 = 0.0f;
      for (int d = 0; d < D; ++d) {
        v2 += particles_.velocity[d][i] * particles_.velocity[d][i];
        acc2 += particles_.acceleration[d][i] * particles_.acceleration[d][i];
      }
      max_speed_ = std::max(max_speed_, std::sqrt(v2));
      a2 = std::max(a2, acc2);
    }
    max_acceleration_ = std::sqrt(a2);
    if (slabs_) {
      max_speed_ = static_cast<float>(slabs_->max(max_speed_));
      max_acceleration_ = static_cast<float>(slabs_->max(max_acceleration_));
    }
  }
  // The surface's nodes count as fluid speed: a moving leaflet must not outrun the step.
  const double speed = std::max<double>(max_speed_, surface_ ? surface_->max_node_speed() : 0.0);
  double dt = s.cfl * h / (s.sound_speed + speed);                             // acoustic
  if (max_acceleration_ > 0) dt = std::min(dt, s.cfl * std::sqrt(h / max_acceleration_));  // force
  if (s.dynamic_viscosity > 0) dt = std::min(dt, 0.125 * h * h * s.rest_density / s.dynamic_viscosity);  // viscous (Morris et al. 1997)
  dt_ = std::min(dt, s.max_time_step);
  double dt_at_rest = std::min(s.cfl * h / s.sound_speed, s.max_time_step);
  if (s.dynamic_viscosity > 0) dt_at_rest = std::min(dt_at_rest, 0.125 * h * h * s.rest_density / s.dynamic_viscosity);
  if (s.min_time_step_ratio > 0 && dt_ < s.min_time_step_ratio * dt_at_rest) {
    const double acoustic = s.cfl * h / (s.sound_speed + speed);
    const char* limit = dt_ == s.max_time_step ? "max_time_step"
                        : dt_ == acoustic      ? "the acoustic limit (speed)"
                        : (s.dynamic_viscosity > 0 && dt_ == 0.125 * h * h * s.rest_density / s.dynamic_viscosity)
                            ? "the viscous limit"
                            : "the force limit (acceleration)";
    throw TimeStepCollapse(fmt::format(
        "time step collapsed at t = {:.6g} s: dt = {:.3g} s < {:g} x the step at rest ({:.3g} s), set by {}; "
        "limits: largest fluid speed {:.3g} m/s, leaflet node speed {:.3g} m/s, largest acceleration {:.3g} m/s^2 "
        "(a particle squeezed between walls or a blow-up); {}; lower the window or the CFL, raise the sound speed, "
        "or set fluid.min_time_step_ratio to go on",
        time_, dt_, s.min_time_step_ratio, dt_at_rest, limit, max_speed_, surface_ ? surface_->max_node_speed() : 0.0,
        max_acceleration_, describe_extremes()));
  }
}

template <int D>
void FluidSolver<D>::check_plate_travel() const {
  for (std::size_t k = 0; k < plates_.size(); ++k) {
    const auto& plate = plates_[k];
    if (plate.displacement >= plate.min_displacement && plate.displacement <= plate.max_displacement) continue;
    double normal_force = 0.0;
    for (int d = 0; d < D; ++d) normal_force += plate.fluid_force[d] * plate.normal[d];
    throw PlateTravelExceeded(fmt::format(
        "pressure plate {} (fluid.plates[{}]) has moved {:.6g} m along its normal by t = {:.6g} s (step {}), outside its "
        "travel_range [{:.6g}, {:.6g}] m: beyond it the plate leaves its channel and the fluid escapes round it; plate "
        "velocity {:.3g} m/s, fluid force along the normal {:.6g} N, prescribed pressure {:.6g} Pa (plus the common level "
        "{:.6g} Pa); find what moves the fluid's volume (a leak past the valve, a density drift) or lengthen the channel "
        "and the plate's travel_range",
        k, k, plate.displacement, time_, steps_, plate.min_displacement, plate.max_displacement, plate.velocity, normal_force,
        plate.pressure(time_), plate_pressure_level(time_)));
  }
}

template <int D>
void FluidSolver<D>::check_leaks() const {
  const ImmersedSurfaceCounters counters = surface_->counters();
  if (counters.leaks <= leak_limit_) return;
  // The counters carry no positions: name the fastest fluid particle near the surface, the
  // likeliest to have gone through it.
  const auto& p = particles_;
  double best = -1.0;
  std::size_t at = 0;
  for (std::size_t i = owned_begin_; i < owned_end_ && i < near_surface_.size(); ++i) {
    if (p.kind[i] != Kind::fluid || !near_surface_[i]) continue;
    double v2 = 0;
    for (int d = 0; d < D; ++d) v2 += static_cast<double>(p.velocity[d][i]) * p.velocity[d][i];
    if (v2 > best) {
      best = v2;
      at = i;
    }
  }
  std::string where = "no fluid particle is near the surface now";
  if (best >= 0)
    where = fmt::format("the fastest fluid particle near the surface is particle {} at x = ({:.6g}, {:.6g}{}) m, speed {:.3g} m/s "
                        "(the surface model counts leaks but does not say which particles)",
                        p.id[at], p.position[0][at], p.position[1][at], D == 3 ? fmt::format(", {:.6g}", p.position[D - 1][at]) : std::string(),
                        std::sqrt(best));
  throw LeakLimitExceeded(fmt::format(
      "fluid leaks through the leaflets: {} particle(s) found on the wrong side of the immersed surface without a put-back "
      "by t = {:.6g} s (step {}), above fluid.max_leak_fraction = {:g} of the {} fluid particles ({} allowed; {} put back so "
      "far); {}; the leaflet moves too far in a step for the put-back or has a gap: lower the coupling window or the fluid "
      "CFL, refine dp, or raise fluid.max_leak_fraction to go on",
      counters.leaks, time_, steps_, settings_.max_leak_fraction, initial_fluid_count_, leak_limit_, counters.corrections, where));
}

template <int D>
std::string FluidSolver<D>::describe_extremes() const {
  // Per rank the own fluid particle of largest acceleration and of largest speed: value, id,
  // position (3), speed, density; the largest over the ranks wins.
  const auto& p = particles_;
  constexpr int kFields = 7;
  std::array<double, 2 * kFields> mine{};
  mine[0] = mine[kFields] = -1.0;
  for (std::size_t i = owned_begin_; i < owned_end_; ++i) {
    if (p.kind[i] != Kind::fluid) continue;
    double v2 = 0, a2 = 0;
    for (int d = 0; d < D; ++d) {
      v2 += static_cast<double>(p.velocity[d][i]) * p.velocity[d][i];
      a2 += static_cast<double>(p.acceleration[d][i]) * p.acceleration[d][i];
    }
    for (int which = 0; which < 2; ++which) {
      const double value = std::sqrt(which == 0 ? a2 : v2);
      double* slot = mine.data() + which * kFields;
      if (value <= slot[0]) continue;
      slot[0] = value;
      slot[1] = p.id[i];
      for (int d = 0; d < 3; ++d) slot[2 + d] = d < D ? p.position[d][i] : 0.0;
      slot[5] = std::sqrt(v2);
      slot[6] = settings_.rest_density + p.density_excess[i];
    }
  }
  std::vector<double> all(mine.begin(), mine.end());
  if (slabs_) {
    all.resize(mine.size() * static_cast<std::size_t>(slabs_->size()));
    MPI_Allgather(mine.data(), 2 * kFields, MPI_DOUBLE, all.data(), 2 * kFields, MPI_DOUBLE, slabs_->communicator());
  }
  std::string text;
  for (int which = 0; which < 2; ++which) {
    const double* best = nullptr;
    for (std::size_t r = 0; r < all.size() / (2 * kFields); ++r) {
      const double* slot = all.data() + r * 2 * kFields + which * kFields;
      if (best == nullptr || slot[0] > best[0]) best = slot;
    }
    if (best == nullptr || best[0] < 0) continue;
    text += fmt::format("{}{} {:.3g} {} at particle {} (x = {:.6g}, {:.6g}{}; speed {:.3g} m/s, density {:.6g} kg/m^3, rest {:g})",
                        text.empty() ? "" : "; ", which == 0 ? "largest acceleration" : "largest speed", best[0],
                        which == 0 ? "m/s^2" : "m/s", static_cast<long>(best[1]), best[2], best[3],
                        D == 3 ? fmt::format(", {:.6g}", best[4]) : std::string(), best[5], best[6], settings_.rest_density);
  }
  return text.empty() ? "no fluid particle" : text;
}

template <int D>
void FluidSolver<D>::advance_to(double end_time) {
  while (time_ < end_time * (1.0 - 1e-12)) {
    if (time_ + dt_ > end_time) dt_ = end_time - time_;
    step();
  }
}

template class FluidSolver<2>;
template class FluidSolver<3>;

}  // namespace valvefsi::fluid
