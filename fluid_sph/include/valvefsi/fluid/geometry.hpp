#pragma once
// Rigid walls from geometric primitives, and the lattice fill that turns a scene into
// particles. Every primitive answers one question: how deep a point lies inside the solid
// (> 0 inside). Fluid and dummy particles sit on one lattice, by default Cartesian at
// origin + (i + 1/2) dp, so a wall face on a lattice plane gets its dummy layers at
// dp/2, 3dp/2, ... behind it and the fluid at dp/2, 3dp/2, ... in front (FillLattice).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "valvefsi/fluid/fluid_settings.hpp"
#include "valvefsi/fluid/particles.hpp"

namespace valvefsi::fluid {

template <int D>
class SolidShape {
 public:
  virtual ~SolidShape() = default;
  // Depth of x inside the solid (m): > 0 inside, <= 0 outside.
  virtual double depth(const Vec<D>& x) const = 0;
};

// Solid everywhere outside the box [lower, upper] (a tank; use a huge upper bound for an
// open top). Depth is the max-norm distance to the box, so corners are filled square.
template <int D>
std::shared_ptr<SolidShape<D>> container_box(const Vec<D>& lower, const Vec<D>& upper);
// Solid inside the box [lower, upper].
template <int D>
std::shared_ptr<SolidShape<D>> solid_box(const Vec<D>& lower, const Vec<D>& upper);
// Solid beyond a plane: the fluid side is where (x - point) . normal > 0.
template <int D>
std::shared_ptr<SolidShape<D>> half_space(const Vec<D>& point, const Vec<D>& normal);
// Solid outside a tube of the given radius whose axis starts at origin and runs `length`
// along `axis` (in 2D: a channel of half-width `radius`).
template <int D>
std::shared_ptr<SolidShape<D>> tube_wall(const Vec<D>& origin, const Vec<D>& axis, double length, double radius);
// Solid ring inner_radius <= r <= outer_radius between axial positions [0, thickness] from
// origin along axis (gasket, skirt; inner_radius = 0 gives a disk, e.g. a plate).
template <int D>
std::shared_ptr<SolidShape<D>> annular_disk(const Vec<D>& origin, const Vec<D>& axis, double thickness,
                                            double inner_radius, double outer_radius);

template <int D>
struct FluidBlock {
  Vec<D> lower{}, upper{};
  // Initial velocity and pressure at a point; unset: at rest, hydrostatic under gravity with
  // the free surface at the block's top.
  std::function<Vec<D>(const Vec<D>&)> velocity;
  std::function<double(const Vec<D>&)> pressure;
};

// The lattice the fill puts particles on (one particle volume dp^D each).
enum class FillLattice {
  cubic,      // origin + (i + 1/2) dp along every axis
  // 3D only: layers dp apart along `lattice_axis` (at origin + (k + 1/2) dp), each a triangular
  // lattice of side a = dp (2/sqrt 3)^(1/2) with rows along `lattice_row_direction` and at 60
  // and 120 degrees to it; the axis through the origin lies halfway between the rows of the
  // first two families (0.465 dp from each). A sector whose cut faces run through the axis
  // along those two families (a 60-degree wedge) then has its first row the same distance from
  // both faces, where a cubic lattice leaves a slab of up to 0.8 dp empty along a face at 30
  // degrees to it.
  hex_prism,
};

template <int D>
struct SceneGeometry {
  std::vector<std::shared_ptr<SolidShape<D>>> walls;   // fixed walls (body 0)
  std::vector<std::shared_ptr<SolidShape<D>>> plates;  // plate k is body k + 1
  std::vector<FluidBlock<D>> fluid;
  Vec<D> lattice_origin{};
  FillLattice lattice = FillLattice::cubic;
  Vec<D> lattice_axis{};           // hex_prism: unit direction of the layer stacking
  Vec<D> lattice_row_direction{};  // hex_prism: unit direction of one row family, normal to the axis
};

// Where the hex-prism lattice fails a mirror plane: an empty string when every plane either
// contains the axis, runs along a row family and lies halfway between two rows, or is normal to
// the axis and lies halfway between two layers; otherwise which plane (its index) and why.
// Also checks the axis and row directions. Empty for the cubic lattice.
template <int D>
std::string fill_lattice_mismatch(const SceneGeometry<D>& scene, const FluidSettings<D>& settings);

// Fluid particles on lattice points inside a fluid block and outside every solid; dummy
// particles on lattice points within `wall_layers` dp inside a wall or plate (default:
// enough layers to fill a kernel support).
template <int D>
Particles<D> fill_particles(const SceneGeometry<D>& scene, const FluidSettings<D>& settings, int wall_layers = 0);

}  // namespace valvefsi::fluid
