#pragma once
// Rigid walls from geometric primitives, and the lattice fill that turns a scene into
// particles. Every primitive answers one question: how deep a point lies inside the solid
// (> 0 inside). Fluid and dummy particles sit on one Cartesian lattice at
// origin + (i + 1/2) dp, so a wall face on a lattice plane gets its dummy layers at
// dp/2, 3dp/2, ... behind it and the fluid at dp/2, 3dp/2, ... in front.
#include <functional>
#include <memory>
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

template <int D>
struct SceneGeometry {
  std::vector<std::shared_ptr<SolidShape<D>>> walls;   // fixed walls (body 0)
  std::vector<std::shared_ptr<SolidShape<D>>> plates;  // plate k is body k + 1
  std::vector<FluidBlock<D>> fluid;
  Vec<D> lattice_origin{};
};

// Fluid particles on lattice points inside a fluid block and outside every solid; dummy
// particles on lattice points within `wall_layers` dp inside a wall or plate (default:
// enough layers to fill a kernel support).
template <int D>
Particles<D> fill_particles(const SceneGeometry<D>& scene, const FluidSettings<D>& settings, int wall_layers = 0);

}  // namespace valvefsi::fluid
