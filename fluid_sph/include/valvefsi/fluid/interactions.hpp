#pragma once
// The physics passes over particle pairs, each one idea:
//   update_fluid_pressure  - the equation of state (eq. 5) for every fluid particle
//   update_wall_state      - generalized wall condition of Adami, Hu & Adams (2012): wall
//                            pressure and no-slip velocity extrapolated from the fluid
//   compute_fluid_rates    - continuity (eq. 2) with delta-SPH diffusion, momentum with
//                            pressure, laminar viscosity (eq. 3) and artificial viscosity
//   compute_body_forces    - the force the fluid exerts on each wall body (action = reaction
//                            of the pair forces of compute_fluid_rates)
//   shifting_density_change - what a particle shift does to the shifted particle's density
// Each pair pass leaves out the pairs an immersed surface blocks (`filter`, inactive by default).
#include <array>
#include <cstddef>
#include <vector>

#include "valvefsi/fluid/cell_grid.hpp"
#include "valvefsi/fluid/fluid_settings.hpp"
#include "valvefsi/fluid/pair_filter.hpp"
#include "valvefsi/fluid/particles.hpp"

namespace valvefsi::fluid {

template <int D>
void update_fluid_pressure(Particles<D>& particles, const FluidSettings<D>& settings);

// body_acceleration[k]: acceleration of body k (0: fixed walls), enters the wall pressure.
template <int D>
void update_wall_state(Particles<D>& particles, const CellGrid<D>& grid, const FluidSettings<D>& settings,
                       const std::vector<Vec<D>>& body_acceleration, const PairFilter<D>& filter = {});

// With body_forces (its size the body count), also the force (N; per unit depth in 2D) of the
// fluid on each body 0..size-1, the fixed walls (body 0) only if include_fixed_walls: booked
// in the same pair loop as the reaction of the fluid-wall pair terms (they are
// antisymmetric), so no second pass over the walls; equal to compute_body_forces to round-off.
// Rates are computed (and reactions booked) only for the particles with sorted index in
// [lane_begin, lane_end): a rank's own particles when the run is split over MPI ranks.
template <int D>
void compute_fluid_rates(Particles<D>& particles, const CellGrid<D>& grid, const FluidSettings<D>& settings,
                         const PairFilter<D>& filter = {}, std::vector<Vec<D>>* body_forces = nullptr,
                         bool include_fixed_walls = false, std::size_t lane_begin = 0,
                         std::size_t lane_end = static_cast<std::size_t>(-1));

// The same forces by a pass of its own over the wall particles (the reference the booked
// forces are tested against; used when there are too many bodies to book).
// Force (N; per unit depth in 2D) of the fluid on each body 0..body_count-1; the fixed walls
// (body 0) only if include_fixed_walls (they are usually most of the dummy particles).
// Only wall particles with fluid in their kernel (update_wall_state marks them) are visited.
template <int D>
std::vector<Vec<D>> compute_body_forces(const Particles<D>& particles, const CellGrid<D>& grid,
                                        const FluidSettings<D>& settings, std::size_t body_count,
                                        bool include_fixed_walls, const PairFilter<D>& filter = {});

// The density change of a particle shift (settings.shifting_density; shift[d][b]: particle b's
// displacement, 0 where it does not move), for the fluid particles with sorted index in
// [begin, end); change[a] = 0 for the others and with ShiftingDensity::keep. Positions are
// those before the shift (the grid's).
// Continuity: particles within a support of an immersed surface get no change here (see the
// source); smooth_shifting_density_change follows.
template <int D>
void shifting_density_change(const Particles<D>& particles, const CellGrid<D>& grid, const FluidSettings<D>& settings,
                             const PairFilter<D>& filter, const std::array<std::vector<double>, D>& shift,
                             std::vector<float>& change, std::size_t begin, std::size_t end);

// Replaces each fluid particle's change in [begin, end) by the Shepard mean sum_b V_b W_ab
// change_b / sum_b V_b W_ab over its fluid neighbours (itself included, blocked pairs left
// out). The continuity change is the divergence of the shift, a particle-scale noisy field
// (the shift is -grad C); its local mean is what moves the fluid's volume. Unsmoothed, the
// 2D valve's leaflet ran away just after the closing (0.319 s). raw: scratch (the input).
template <int D>
void smooth_shifting_density_change(const Particles<D>& particles, const CellGrid<D>& grid, const FluidSettings<D>& settings,
                                    const PairFilter<D>& filter, std::vector<float>& change, std::vector<float>& raw,
                                    std::size_t begin, std::size_t end);

}  // namespace valvefsi::fluid
