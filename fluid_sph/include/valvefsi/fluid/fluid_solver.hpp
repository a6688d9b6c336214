#pragma once
// The weakly compressible SPH solver: owns the particles, the cell grid and the moving
// bodies, and advances them with a kick-drift-kick velocity-Verlet step. An optional
// immersed-surface model (the leaflets) joins the step in the order its header prescribes.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "valvefsi/fluid/cell_grid.hpp"
#include "valvefsi/fluid/fluid_settings.hpp"
#include "valvefsi/fluid/immersed_surface.hpp"
#include "valvefsi/fluid/mirror_group.hpp"
#include "valvefsi/fluid/pair_filter.hpp"
#include "valvefsi/fluid/particles.hpp"
#include "valvefsi/fluid/pressure_plate.hpp"
#include "valvefsi/fluid/slab_decomposition.hpp"

namespace valvefsi::fluid {

// A run the solver stops itself: what() says what failed, when, where and what to change. The
// solver's state is that of the last completed step (finite), so it can still be written.
class FluidStop : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Thrown when the time step falls below FluidSettings::min_time_step_ratio of the step at rest;
// what() says which limit, and where the fastest and the most accelerated particles are.
class TimeStepCollapse : public FluidStop {
 public:
  using FluidStop::FluidStop;
};

// Thrown when the immersed surface's leak count (particles found on the wrong side of a leaflet
// without a put-back) exceeds FluidSettings::max_leak_fraction of the fluid particles.
class LeakLimitExceeded : public FluidStop {
 public:
  using FluidStop::FluidStop;
};

// Thrown when a pressure plate's displacement leaves its [min_displacement, max_displacement].
class PlateTravelExceeded : public FluidStop {
 public:
  using FluidStop::FluidStop;
};

template <int D>
class FluidSolver {
 public:
  // Wall particles with body k > 0 belong to plates[k - 1]; body 0 walls are fixed. Throws
  // std::invalid_argument for mirror planes whose reflections generate an infinite group.
  FluidSolver(const FluidSettings<D>& settings, Particles<D> particles, std::vector<PressurePlate<D>> plates = {},
              std::unique_ptr<ImmersedSurfaceModel<D>> surface = nullptr);

  // Installs (or removes, with nullptr) the immersed-surface model and re-evaluates the rates
  // of the current state with it.
  void set_immersed_surface(std::unique_ptr<ImmersedSurfaceModel<D>> surface);
  ImmersedSurfaceModel<D>* immersed_surface() { return surface_.get(); }
  const ImmersedSurfaceModel<D>* immersed_surface() const { return surface_.get(); }
  // The surface model's node forces averaged over the steps since the last reset, weighted by
  // each step's length (what a coupling window sends); empty without a surface.
  void reset_surface_force_average();
  std::vector<Vec<D>> surface_force_average() const;

  // Saves / restores the whole state (particles, plates, time, step, the surface model's own
  // checkpoint), so an implicit coupling scheme can repeat a window.
  void save_checkpoint();
  void restore_checkpoint();
  bool has_checkpoint() const { return checkpoint_ != nullptr; }

  // Restart files (docs/coupling.md, "Restarts"): the whole state as named arrays, such that
  // load_restart_state on a solver built from the same case (and, with a surface, the same
  // surface geometry already installed) continues bit for bit. The particles keep their order
  // with every field and scratch array a step reads, the cell ranges of the last sort, plates,
  // time, dt, step count, lost counters, the window's surface-force sums, and the surface
  // model's own restart_state() under the prefix "surface/". std::nullopt when the surface
  // model cannot restart (the solver then cannot either).
  std::optional<std::vector<NamedArray>> restart_state() const;
  // Throws std::runtime_error naming the array that is missing or of the wrong size.
  void load_restart_state(std::span<const NamedArray> arrays);

  // Splits the run over the ranks of `comm` (collective; right after construction, before the
  // first step): slabs of cell layers along the last axis (SlabDecomposition). With one rank
  // nothing changes. Throws std::invalid_argument for what it cannot split: an immersed
  // surface, a mirror plane whose normal has a component along the slab axis, a periodic slab
  // axis, more ranks than the layers allow.
  void decompose(MPI_Comm comm);
  // nullptr when the run is not split.
  const SlabDecomposition<D>* decomposition() const { return slabs_.get(); }
  // This rank's own particles (sorted indices [first, second)); all particles on one rank.
  // The rest of particles() is halo (copies of the neighbours' particles), mirror images and,
  // split, the lost particles at the end.
  std::pair<std::size_t, std::size_t> owned_range() const { return {owned_begin_, owned_end_}; }

  // Advances by time_step() and then chooses the next time step. Throws FluidStop (a
  // TimeStepCollapse or a LeakLimitExceeded) when the run cannot go on.
  void step();
  // Steps until time() >= end_time (the last step is shortened to land on it).
  void advance_to(double end_time);

  double time() const { return time_; }
  double time_step() const { return dt_; }
  long step_count() const { return steps_; }
  // Particles taken out of the run: left the domain, or density out of range (of those).
  std::size_t lost_count() const { return lost_; }
  std::size_t density_out_of_range_count() const { return lost_density_; }
  // The first kNamedLosses particles this process took out for their density, with where and
  // how (the count above goes on; the programs log each as it appears): what an investigation
  // of a loss needs without tracing the particle through snapshots.
  struct TakenOut {
    std::uint32_t id = 0;
    double time = 0.0;      // s
    long step = 0;
    Vec<D> position{};      // m
    double density = 0.0;   // kg/m^3
    double speed = 0.0;     // m/s
    bool near_surface = false;  // within a support of the immersed surface (leaflets)
  };
  static constexpr std::size_t kNamedLosses = 200;
  const std::vector<TakenOut>& named_losses() const { return named_losses_; }
  const FluidSettings<D>& settings() const { return settings_; }
  const Particles<D>& particles() const { return particles_; }
  const CellGrid<D>& grid() const { return grid_; }
  const std::vector<PressurePlate<D>>& plates() const { return plates_; }
  // The common level added to every plate's prescribed pressure at time t (Pa): with
  // settings().plates_never_pull the least that keeps every plate's absolute pressure at or
  // above settings().plate_pressure_floor (0 while a plate_floor_once_reached floor has not
  // been reached by time()), else 0.
  double plate_pressure_level(double t) const;
  double plate_pressure_level() const { return plate_pressure_level(time_); }
  // Whether the lowest plate's absolute drive has reached settings().plate_pressure_floor at
  // some step so far (always true without plate_floor_once_reached).
  bool plate_floor_reached() const { return plate_floor_reached_; }

  // Force of the fluid on body k (0: fixed walls, k: plates[k-1]) at the last step that
  // computed it: plates every step; the fixed walls only after request_body_forces() or
  // with compute_body_forces_every_step(true) (otherwise their entry stays zero).
  const std::vector<Vec<D>>& body_forces() const { return body_forces_; }
  void request_body_forces() { body_forces_requested_ = true; }
  void compute_body_forces_every_step(bool on) { body_forces_always_ = on; }

 private:
  void evaluate_rates();
  void choose_time_step();
  void shift_particles(double dt);
  void classify_surface();
  void refresh_mirror_images();
  void drop_mirror_images_and_reflect();
  void add_mirror_images();
  void update_owned_range();
  std::string describe_extremes() const;
  void check_leaks() const;
  void check_plate_travel() const;
  double lowest_plate_drive(double t) const;  // min over plates of prescribed + background (Pa)
  void note_plate_floor(double t);
  PairFilter<D> pair_filter() const;

  struct Checkpoint;

  FluidSettings<D> settings_;
  Particles<D> particles_;
  std::vector<PressurePlate<D>> plates_;
  CellGrid<D> grid_;
  std::vector<Vec<D>> body_forces_;
  std::vector<Vec<D>> body_acceleration_;
  bool body_forces_requested_ = false;
  bool body_forces_always_ = false;
  std::vector<std::uint32_t> mirror_keep_;  // scratch of refresh_mirror_images
  std::vector<MirrorMap<D>> compound_mirror_maps_;  // images of images where planes cross
  double time_ = 0.0;
  double dt_ = 0.0;
  long steps_ = 0;
  std::size_t lost_ = 0;
  std::size_t lost_density_ = 0;
  std::vector<TakenOut> named_losses_;
  bool plate_floor_reached_ = true;  // false from construction while a once-reached floor waits
  float max_speed_ = 0.0f;
  float max_acceleration_ = 0.0f;
  std::unique_ptr<ImmersedSurfaceModel<D>> surface_;
  std::vector<std::uint8_t> near_surface_;  // per sorted particle, after classify
  std::array<std::vector<double>, D> shift_;  // scratch of shift_particles: each particle's shift
  std::vector<float> shift_density_change_;   // scratch of shift_particles: the shift's density change
  std::vector<float> shift_density_scratch_;  // scratch of shift_particles
  std::vector<Vec<D>> surface_force_sum_;   // sum of node force x dt since the reset
  double surface_force_time_ = 0.0;
  std::vector<Vec<D>> surface_force_scratch_;
  std::shared_ptr<Checkpoint> checkpoint_;
  std::unique_ptr<SlabDecomposition<D>> slabs_;
  std::size_t owned_begin_ = 0, owned_end_ = 0;
  std::size_t initial_fluid_count_ = 0;
  std::size_t leak_limit_ = 0;  // leaks allowed: max_leak_fraction x the fluid particles at the start
};

}  // namespace valvefsi::fluid
