#pragma once
// Particles in structure-of-arrays form: one contiguous array per component, so the pair
// loops read neighbours as unit-stride streams the compiler can vectorise. Positions are
// double (a 1 m domain at 0.5 mm spacing needs more than float's 7 digits for small
// displacements per step); all other fields are float.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace valvefsi::fluid {

template <int D>
using Vec = std::array<double, D>;

enum class Kind : std::uint8_t {
  fluid = 0,
  wall = 1,  // dummy particle of a rigid wall or moving body (generalized wall condition)
  lost = 2,  // left a non-periodic domain; excluded from all interactions and counted
  // Mirror images across a symmetry plane, rebuilt every step from the particles within a
  // kernel support of the plane; neighbours only, never integrated, probed or counted.
  mirror_fluid = 3,  // acts as fluid in the pair sums (pressure from its density)
  mirror_wall = 4,   // acts as a wall (its own wall state); no force is booked on it
};

// Whether particles of this kind enter the pair sums as fluid.
inline bool acts_as_fluid(Kind k) { return k == Kind::fluid || k == Kind::mirror_fluid; }
inline bool is_mirror(Kind k) { return k == Kind::mirror_fluid || k == Kind::mirror_wall; }

template <int D>
struct Particles {
  std::array<std::vector<double>, D> position;
  // Fluid: velocity. Wall: the wall's own velocity (enters the continuity equation).
  std::array<std::vector<float>, D> velocity;
  // Fluid: equal to velocity. Wall: the no-slip velocity 2 v_wall - v_fluid_extrapolated.
  std::array<std::vector<float>, D> viscous_velocity;
  std::array<std::vector<float>, D> acceleration;
  std::vector<float> density_excess;  // rho - rho0 (kg/m^3)
  std::vector<float> density_rate;    // d rho / dt (kg/m^3/s)
  std::vector<float> density_rate_previous;  // the rate of the previous step (integrator)
  std::vector<float> pressure;        // Pa
  std::vector<Kind> kind;
  std::vector<std::uint16_t> body;    // 0: fluid or fixed wall; k > 0: moving body k - 1
  std::vector<std::uint32_t> id;      // stable identity across re-sorting

  // Scratch for the pair loops, rebuilt after every sort (not permuted, not output):
  // float positions relative to the grid's lower corner (float resolves 4 m to 0.5 um, far
  // below any spacing, and halves the loop's memory traffic), and 1 for fluid, 0 otherwise.
  std::array<std::vector<float>, D> local_position;
  std::vector<float> fluid_mask;
  std::vector<float> inverse_density;  // 1 / rho, set with the pressure each evaluation
  std::vector<std::uint8_t> near_fluid;  // walls: 1 if a fluid particle is within the support
  std::vector<std::uint8_t> near_wall;   // mirror fluid: 1 if a wall (not an image) may be within the support
  std::vector<float> kernel_sum;                          // C = sum_b V_b W_ab (shifting only)
  std::array<std::vector<float>, D> kernel_sum_gradient;  // grad C (shifting only)

  std::size_t size() const { return kind.size(); }

  // Appends a particle at rest with the given density excess.
  void add(const Vec<D>& x, const std::array<float, D>& v, float density_excess_value, Kind k,
           std::uint16_t body_index = 0) {
    for (int d = 0; d < D; ++d) {
      position[d].push_back(x[d]);
      velocity[d].push_back(v[d]);
      viscous_velocity[d].push_back(v[d]);
      acceleration[d].push_back(0.0f);
    }
    density_excess.push_back(density_excess_value);
    density_rate.push_back(0.0f);
    density_rate_previous.push_back(0.0f);
    pressure.push_back(0.0f);
    kind.push_back(k);
    body.push_back(body_index);
    id.push_back(static_cast<std::uint32_t>(id.size()));
  }

  // Calls f(array) for every per-particle array, e.g. to permute them all the same way.
  template <class F>
  void for_each_array(F&& f) {
    for (int d = 0; d < D; ++d) {
      f(position[d]);
      f(velocity[d]);
      f(viscous_velocity[d]);
      f(acceleration[d]);
    }
    f(density_excess);
    f(density_rate);
    f(density_rate_previous);
    f(pressure);
    f(kind);
    f(body);
    f(id);
  }

  // Calls f(mine, theirs) for every per-particle array of this set and of `other`.
  template <class F>
  void for_each_array_with(Particles& other, F&& f) {
    for (int d = 0; d < D; ++d) {
      f(position[d], other.position[d]);
      f(velocity[d], other.velocity[d]);
      f(viscous_velocity[d], other.viscous_velocity[d]);
      f(acceleration[d], other.acceleration[d]);
    }
    f(density_excess, other.density_excess);
    f(density_rate, other.density_rate);
    f(density_rate_previous, other.density_rate_previous);
    f(pressure, other.pressure);
    f(kind, other.kind);
    f(body, other.body);
    f(id, other.id);
  }

  // The same for the arrays a re-sort must carry along: all but the acceleration, the
  // density rate and the viscous velocity, which every rate evaluation rebuilds before they
  // are read (fluid: viscous velocity = velocity, set after the sort; walls: the wall state).
  template <class F>
  void for_each_sorted_array_with(Particles& other, F&& f) {
    for (int d = 0; d < D; ++d) {
      f(position[d], other.position[d]);
      f(velocity[d], other.velocity[d]);
    }
    f(density_excess, other.density_excess);
    f(density_rate_previous, other.density_rate_previous);
    f(pressure, other.pressure);
    f(kind, other.kind);
    f(body, other.body);
    f(id, other.id);
  }

  std::size_t count(Kind k) const {
    std::size_t n = 0;
    for (Kind x : kind) n += (x == k);
    return n;
  }
};

}  // namespace valvefsi::fluid
