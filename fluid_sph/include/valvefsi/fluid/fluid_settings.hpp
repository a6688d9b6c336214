#pragma once
// Physical and numerical parameters of one fluid simulation (SI units throughout).
#include <array>
#include <limits>
#include <vector>

#include "valvefsi/fluid/kernels.hpp"
#include "valvefsi/fluid/particles.hpp"

namespace valvefsi::fluid {

// A symmetry plane: the fluid lies on the side the normal points to; the other side holds the
// fluid's mirror image (no flux through the plane, no shear stress on it).
template <int D>
struct MirrorPlane {
  Vec<D> point{};   // m
  Vec<D> normal{};  // unit, towards the fluid
};

template <int D>
struct FluidSettings {
  double particle_spacing = 0.0;        // dp (m)
  double smoothing_length_ratio = 1.3;  // h / dp
  KernelType kernel = KernelType::cubic_spline;
  double rest_density = 1056.0;         // rho0 (kg/m^3), blood
  double dynamic_viscosity = 0.0035;    // mu (Pa s), blood
  double sound_speed = 145.0;           // artificial c0 (m/s), the reference's value
  double density_diffusion = 0.1;       // delta of the delta-SPH term (Molteni & Colagrossi 2009)
  double artificial_viscosity = 0.0;    // alpha of Monaghan's artificial viscosity
  // Constant pressure added to the equation of state (Pa). It does not change the pressure
  // gradient but keeps the pair forces repulsive where the gauge pressure is negative, which
  // suppresses the tensile instability; probes, output and plate loads report p - background.
  double background_pressure = 0.0;
  // Plates that never pull (issue 7): at every instant all plates' prescribed pressures are
  // raised by one common level, the least that keeps the lowest plate's absolute pressure
  // (prescribed + background) at or above plate_pressure_floor. The flow is driven by pressure
  // differences only, so it is unchanged, but no plate is driven into tension the blood cannot
  // hold (a plate driven below the fluid's zero pulls away from it and flies off). The fluid
  // carries the level as a real compression, Delta rho / rho0 = level / (rho0 c0^2); pressure
  // probes and snapshots report p - background - level (the waveform's reference).
  bool plates_never_pull = false;
  double plate_pressure_floor = 0.0;  // Pa
  // With plates_never_pull: until the lowest plate's absolute drive first reaches
  // plate_pressure_floor the floor is 0 (the plates only never pull); from then on the floor
  // holds. A drive that starts below the floor then starts as without one, and the floor still
  // catches a plate that the closing water hammer kicks away from the blood.
  bool plate_floor_once_reached = false;
  Vec<D> gravity{};                     // body acceleration (m/s^2)
  // Particle shifting: each step a fluid particle moves by -A h U dt grad C, with C the kernel
  // sum, A this coefficient (0: off) and U a speed (shifting_speed), capped at
  // max_shift_fraction dp. It keeps the particle distribution regular where the flow stretches
  // it (vortices, stagnation points, edges). Skipped near a free surface (C below
  // free_surface_kernel_sum).
  double shifting = 0.0;
  double max_shift_fraction = 0.05;
  // U of the shift. fastest_particle: the largest fluid speed in the run, the same for every
  // particle (robust where the fastest flow is, but fluid at rest moves wherever grad C is not
  // 0, which a flow section counts as no flux). own_speed: the particle's own speed (Skillen et
  // al. 2013), so fluid at rest stays put (docs/fluid_sph.md, "Shifting's speed").
  // own_speed_away_from_surfaces: the fastest speed within a support of an immersed surface
  // (the leaflets' slow layers need the regularisation), the own speed elsewhere.
  enum class ShiftingSpeed { fastest_particle, own_speed, own_speed_away_from_surfaces };
  ShiftingSpeed shifting_speed = ShiftingSpeed::fastest_particle;
  // What a shift does to the shifted particle's density (docs/fluid_sph.md, "Shifting and
  // density"). keep: nothing (the particles move, their density stays: where the shift spreads
  // particles apart their density ends above their packing). field_gradient: the particle takes
  // the density field's value at its new position, rho += grad rho . dr with the renormalised
  // gradient of the fluid's densities (the ALE form of delta+-SPH, Sun et al. 2017).
  // continuity: the continuity equation applied to the shift's displacement,
  // m sum_b (dr_a - dr_b) . grad_a W_ab (walls and mirror images do not move; none of its own
  // within a support of an immersed surface), averaged over the kernel (Shepard), so the
  // density follows the packing the shift makes. One MPI rank only.
  enum class ShiftingDensity { keep, field_gradient, continuity };
  ShiftingDensity shifting_density = ShiftingDensity::keep;
  double free_surface_kernel_sum = 0.9;
  // A fluid particle whose |rho - rho0| exceeds this fraction of rho0 is taken out of the
  // run (counted as lost), as DualSPHysics does with RhopOutMin/Max (700-1300 for water).
  double max_density_deviation = 0.3;
  // Stop when dt < this x the step at rest (acoustic, viscous, max_time_step; 0: never).
  double min_time_step_ratio = 1e-3;
  // Stop when the immersed surface's leaks (particles on the wrong side of a leaflet without a
  // put-back: mass through a closed valve) exceed this fraction of the fluid particles at the
  // start (LeakLimitExceeded). 1e-3 lets the odd isolated leak pass (session 4's 2D MHGO valve
  // leaked 1 particle in two cycles) and stops a leaflet that has become porous: 0.1 % of the
  // blood through a closed valve is a volume of the order of the closing regurgitation itself.
  double max_leak_fraction = 1e-3;
  double cfl = 0.2;                     // Courant number of the acoustic and force limits
  double max_time_step = std::numeric_limits<double>::infinity();  // s
  int sort_interval = 1;                // re-sort particles by cell every this many steps
  Vec<D> domain_lower{};                // particles leaving [lower, upper) on a non-periodic axis are lost
  Vec<D> domain_upper{};
  std::array<bool, D> periodic{};
  // Symmetry planes at any angle (e.g. the two cut faces of a valve sector). The domain must
  // reach a kernel support beyond each plane, where the mirror images live. Where planes cross
  // (a sector's axis) the images of images are made too: the whole finite group the
  // reflections generate (mirror_group.hpp); planes that generate an infinite group are refused.
  std::vector<MirrorPlane<D>> mirror_planes;
  // false: only each plane's own reflection (the fluid at a sector's axis then misses
  // neighbours); kept to show what the images of images fix.
  bool mirror_images_of_images = true;

  double smoothing_length() const { return smoothing_length_ratio * particle_spacing; }
  double support_radius() const { return 2.0 * smoothing_length(); }
  double particle_mass() const {
    double volume = 1.0;
    for (int d = 0; d < D; ++d) volume *= particle_spacing;
    return rest_density * volume;
  }
};

}  // namespace valvefsi::fluid
