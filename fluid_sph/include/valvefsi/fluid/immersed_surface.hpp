#pragma once
// The hook through which FluidSolver lets a model of thin immersed surfaces (the leaflets)
// act on the fluid. The solver owns the particles and the step; the model owns the surface,
// its wall state and the loads on it. The fluid library knows only this interface, so the
// surface model can be swapped, and the library does not depend on any one model (the
// two-sided thin wall in fluid_sph/thin_wall implements it).
//
// Call order inside FluidSolver<D>::step() (kick-drift-kick), docs/thin-leaflet.md:
//   begin_step -> kick -> drift -> move_to(t + dt) -> correct_crossings -> sort ->
//   classify -> [fluid pressure] -> update_surface_states -> fluid-fluid pass (pairs with
//   blocked() == true left out; only pairs with a near_surface() particle need the test) ->
//   add_surface_rates -> kick; shifting asks accept_shift for every near-surface particle.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "valvefsi/fluid/cell_grid.hpp"
#include "valvefsi/fluid/particles.hpp"

namespace valvefsi::fluid {

// A surface as the coupler sends it (coupling.proto InterfaceSurface), in the fluid's
// dimension: segments (2 nodes per cell) in 2D, triangles (3) in 3D.
template <int D>
struct ImmersedSurfaceGeometry {
  std::vector<Vec<D>> nodes;                // m
  int nodes_per_cell = D;                   // 2: segments, 3: triangles
  std::vector<std::uint32_t> cells;         // nodes_per_cell entries per cell, 0-based
  std::vector<double> node_thickness;       // m, one per node
};

// One entry of a model's restart state: a name unique within the model and its values
// (integers stored as doubles, exact up to 2^53).
struct NamedArray {
  std::string name;
  std::vector<double> values;
};

struct ImmersedSurfaceCounters {
  std::size_t corrections = 0;      // particles put back after crossing the surface
  std::size_t leaks = 0;            // particles found on the wrong side without a correction
  std::size_t rejected_shifts = 0;  // shifts refused because they would cross or touch it
};

template <int D>
class ImmersedSurfaceModel {
 public:
  virtual ~ImmersedSurfaceModel() = default;

  // --- motion -----------------------------------------------------------------------
  // The motion the surface must reach at the end of the coupling window [now, end_time]:
  // node positions and velocities at end_time (what the coupler sends). The model moves the
  // nodes from their current state to this one as the solver calls move_to.
  virtual void set_window_target(double end_time, std::span<const Vec<D>> end_positions,
                                 std::span<const Vec<D>> end_velocities) = 0;
  // Places the nodes at `time` (positions, velocities and the accelerations the wall
  // condition needs).
  virtual void move_to(double time) = 0;
  // Largest node speed (m/s), for the solver's time-step limit.
  virtual double max_node_speed() const = 0;

  // --- the step -----------------------------------------------------------------------
  virtual void begin_step(const Particles<D>& particles) = 0;
  virtual void correct_crossings(Particles<D>& particles) = 0;
  virtual void classify(const Particles<D>& particles) = 0;
  // Whether particle i (sorted index, after classify) is within a kernel support of the
  // surface: only pairs with such a particle can be blocked.
  virtual bool near_surface(std::size_t i) const = 0;
  // True when particles a and b must not interact (they are on opposite sides).
  virtual bool blocked(std::uint32_t a, std::uint32_t b, const Particles<D>& particles) const = 0;
  virtual void update_surface_states(const Particles<D>& particles, const CellGrid<D>& grid) = 0;
  // Adds the surface's terms to the fluid's rates (after the fluid-fluid pass) and sets the
  // reaction loads on the surface.
  virtual void add_surface_rates(Particles<D>& particles) = 0;
  virtual bool accept_shift(const Particles<D>& particles, std::size_t i, const Vec<D>& shift) = 0;

  // --- loads and diagnostics ------------------------------------------------------------
  virtual std::size_t node_count() const = 0;
  // Force of the fluid on each node at the last add_surface_rates (N; N per metre of depth
  // in 2D). Their sum is minus the force the surface exerted on the fluid.
  virtual void node_forces(std::span<Vec<D>> forces) const = 0;
  virtual ImmersedSurfaceCounters counters() const = 0;

  // --- implicit coupling: repeat a window -------------------------------------------------
  virtual void save_checkpoint() = 0;
  virtual void restore_checkpoint() = 0;

  // --- restart files (docs/coupling.md, "Restarts") --------------------------------------
  // The model's whole state at a window's end, beyond the geometry the handshake gives again
  // (node positions and velocities, the window's motion, counters, per-particle flags in
  // the particle order of the moment: the fluid restores its particles in that same order),
  // such that load_restart_state on a model built from the same geometry continues bit for
  // bit. The fluid stores the arrays in its
  // restart file under a prefix. std::nullopt: this model cannot restart (the default), and
  // the fluid refuses to take part in restarts, saying so.
  virtual std::optional<std::vector<NamedArray>> restart_state() const { return std::nullopt; }
  // Called once, after the model is built and before the first step of the restarted run;
  // throws std::runtime_error naming the array that is missing or of the wrong size.
  virtual void load_restart_state(std::span<const NamedArray> arrays) {
    (void)arrays;
    throw std::runtime_error("this immersed-surface model cannot load restart state");
  }
};

}  // namespace valvefsi::fluid
