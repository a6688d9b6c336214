#include "valvefsi/fluid/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "valvefsi/fluid/equation_of_state.hpp"

namespace valvefsi::fluid {
namespace {

template <int D>
double dot(const Vec<D>& a, const Vec<D>& b) {
  double s = 0;
  for (int d = 0; d < D; ++d) s += a[d] * b[d];
  return s;
}

template <int D>
Vec<D> unit(const Vec<D>& a, const char* what) {
  const double n = std::sqrt(dot<D>(a, a));
  if (!(n > 0)) throw std::invalid_argument(std::string(what) + ": direction vector must be non-zero");
  Vec<D> u;
  for (int d = 0; d < D; ++d) u[d] = a[d] / n;
  return u;
}

// Axial coordinate and distance from the axis.
template <int D>
std::pair<double, double> axial_radial(const Vec<D>& x, const Vec<D>& origin, const Vec<D>& axis) {
  Vec<D> rel;
  for (int d = 0; d < D; ++d) rel[d] = x[d] - origin[d];
  const double along = dot<D>(rel, axis);
  double r2 = 0;
  for (int d = 0; d < D; ++d) {
    const double perp = rel[d] - along * axis[d];
    r2 += perp * perp;
  }
  return {along, std::sqrt(r2)};
}

template <int D>
class ContainerBox final : public SolidShape<D> {
 public:
  ContainerBox(const Vec<D>& lo, const Vec<D>& hi) : lo_(lo), hi_(hi) {}
  double depth(const Vec<D>& x) const override {
    double outside = 0;
    for (int d = 0; d < D; ++d) outside = std::max({outside, lo_[d] - x[d], x[d] - hi_[d]});
    return outside;
  }
 private:
  Vec<D> lo_, hi_;
};

template <int D>
class SolidBox final : public SolidShape<D> {
 public:
  SolidBox(const Vec<D>& lo, const Vec<D>& hi) : lo_(lo), hi_(hi) {}
  double depth(const Vec<D>& x) const override {
    double inside = std::numeric_limits<double>::infinity();
    for (int d = 0; d < D; ++d) inside = std::min({inside, x[d] - lo_[d], hi_[d] - x[d]});
    return inside;
  }
 private:
  Vec<D> lo_, hi_;
};

template <int D>
class HalfSpace final : public SolidShape<D> {
 public:
  HalfSpace(const Vec<D>& point, const Vec<D>& normal) : point_(point), normal_(unit<D>(normal, "half_space normal")) {}
  double depth(const Vec<D>& x) const override {
    Vec<D> rel;
    for (int d = 0; d < D; ++d) rel[d] = x[d] - point_[d];
    return -dot<D>(rel, normal_);
  }
 private:
  Vec<D> point_, normal_;
};

template <int D>
class TubeWall final : public SolidShape<D> {
 public:
  TubeWall(const Vec<D>& origin, const Vec<D>& axis, double length, double radius)
      : origin_(origin), axis_(unit<D>(axis, "tube axis")), length_(length), radius_(radius) {}
  double depth(const Vec<D>& x) const override {
    const auto [along, r] = axial_radial<D>(x, origin_, axis_);
    if (along < 0 || along > length_) return 0.0;
    return r - radius_;
  }
 private:
  Vec<D> origin_, axis_;
  double length_, radius_;
};

template <int D>
class AnnularDisk final : public SolidShape<D> {
 public:
  AnnularDisk(const Vec<D>& origin, const Vec<D>& axis, double thickness, double inner, double outer)
      : origin_(origin), axis_(unit<D>(axis, "annular disk axis")), thickness_(thickness), inner_(inner), outer_(outer) {}
  double depth(const Vec<D>& x) const override {
    const auto [along, r] = axial_radial<D>(x, origin_, axis_);
    return std::min({along, thickness_ - along, r - inner_, outer_ - r});
  }
 private:
  Vec<D> origin_, axis_;
  double thickness_, inner_, outer_;
};

}  // namespace

template <int D>
std::shared_ptr<SolidShape<D>> container_box(const Vec<D>& lower, const Vec<D>& upper) {
  return std::make_shared<ContainerBox<D>>(lower, upper);
}
template <int D>
std::shared_ptr<SolidShape<D>> solid_box(const Vec<D>& lower, const Vec<D>& upper) {
  return std::make_shared<SolidBox<D>>(lower, upper);
}
template <int D>
std::shared_ptr<SolidShape<D>> half_space(const Vec<D>& point, const Vec<D>& normal) {
  return std::make_shared<HalfSpace<D>>(point, normal);
}
template <int D>
std::shared_ptr<SolidShape<D>> tube_wall(const Vec<D>& origin, const Vec<D>& axis, double length, double radius) {
  return std::make_shared<TubeWall<D>>(origin, axis, length, radius);
}
template <int D>
std::shared_ptr<SolidShape<D>> annular_disk(const Vec<D>& origin, const Vec<D>& axis, double thickness, double inner_radius,
                                            double outer_radius) {
  return std::make_shared<AnnularDisk<D>>(origin, axis, thickness, inner_radius, outer_radius);
}

template <int D>
Particles<D> fill_particles(const SceneGeometry<D>& scene, const FluidSettings<D>& s, int wall_layers) {
  const double dp = s.particle_spacing;
  if (wall_layers <= 0) wall_layers = static_cast<int>(std::ceil(s.support_radius() / dp - 1e-9));
  const double wall_thickness = wall_layers * dp;
  const LinearMieGruneisen eos{s.rest_density, s.sound_speed};

  std::array<long, D> first{}, count{};
  long total = 1;
  for (int d = 0; d < D; ++d) {
    first[d] = static_cast<long>(std::ceil((s.domain_lower[d] - scene.lattice_origin[d]) / dp - 0.5 - 1e-9));
    const long last = static_cast<long>(std::floor((s.domain_upper[d] - scene.lattice_origin[d]) / dp - 0.5 - 1e-9));
    count[d] = std::max(0L, last - first[d] + 1);
    total *= count[d];
  }

  Particles<D> particles;
  const double tiny = 1e-9 * dp;
  for (long flat = 0; flat < total; ++flat) {
    Vec<D> x;
    long rest = flat;
    for (int d = 0; d < D; ++d) {
      x[d] = scene.lattice_origin[d] + (static_cast<double>(first[d] + rest % count[d]) + 0.5) * dp;
      rest /= count[d];
    }
    // Beyond a mirror plane live only images. Points closer than 0.4 dp to a plane are left
    // out too: their images would sit almost on them (a plane on a lattice plane keeps its
    // first layer, at dp/2).
    bool mirrored_away = false;
    for (const auto& plane : s.mirror_planes) {
      double distance = 0;
      for (int d = 0; d < D; ++d) distance += (x[d] - plane.point[d]) * plane.normal[d];
      mirrored_away = mirrored_away || distance < 0.4 * dp;
    }
    if (mirrored_away) continue;
    // Plates first, then fixed walls, then fluid.
    int plate = -1;
    for (std::size_t k = 0; k < scene.plates.size() && plate < 0; ++k)
      if (scene.plates[k]->depth(x) > tiny) plate = static_cast<int>(k);
    if (plate >= 0) {
      particles.add(x, {}, 0.0f, Kind::wall, static_cast<std::uint16_t>(plate + 1));
      continue;
    }
    double wall_depth = 0;
    for (const auto& w : scene.walls) wall_depth = std::max(wall_depth, w->depth(x));
    if (wall_depth > tiny) {
      if (wall_depth < wall_thickness) particles.add(x, {}, 0.0f, Kind::wall, 0);
      continue;
    }
    for (const auto& block : scene.fluid) {
      bool inside = true;
      for (int d = 0; d < D; ++d) inside = inside && x[d] > block.lower[d] && x[d] < block.upper[d];
      if (!inside) continue;
      double pressure = 0;
      if (block.pressure) {
        pressure = block.pressure(x);
      } else {
        // Hydrostatic with the free surface at the block's top (the corner against gravity).
        for (int d = 0; d < D; ++d) {
          const double top = s.gravity[d] < 0 ? block.upper[d] : block.lower[d];
          pressure += s.rest_density * s.gravity[d] * (x[d] - top);
        }
      }
      std::array<float, D> v{};
      if (block.velocity) {
        const Vec<D> u = block.velocity(x);
        for (int d = 0; d < D; ++d) v[d] = static_cast<float>(u[d]);
      }
      particles.add(x, v, static_cast<float>(eos.density_excess(pressure)), Kind::fluid, 0);
      break;
    }
  }
  return particles;
}

template std::shared_ptr<SolidShape<2>> container_box<2>(const Vec<2>&, const Vec<2>&);
template std::shared_ptr<SolidShape<3>> container_box<3>(const Vec<3>&, const Vec<3>&);
template std::shared_ptr<SolidShape<2>> solid_box<2>(const Vec<2>&, const Vec<2>&);
template std::shared_ptr<SolidShape<3>> solid_box<3>(const Vec<3>&, const Vec<3>&);
template std::shared_ptr<SolidShape<2>> half_space<2>(const Vec<2>&, const Vec<2>&);
template std::shared_ptr<SolidShape<3>> half_space<3>(const Vec<3>&, const Vec<3>&);
template std::shared_ptr<SolidShape<2>> tube_wall<2>(const Vec<2>&, const Vec<2>&, double, double);
template std::shared_ptr<SolidShape<3>> tube_wall<3>(const Vec<3>&, const Vec<3>&, double, double);
template std::shared_ptr<SolidShape<2>> annular_disk<2>(const Vec<2>&, const Vec<2>&, double, double, double);
template std::shared_ptr<SolidShape<3>> annular_disk<3>(const Vec<3>&, const Vec<3>&, double, double, double);
template Particles<2> fill_particles<2>(const SceneGeometry<2>&, const FluidSettings<2>&, int);
template Particles<3> fill_particles<3>(const SceneGeometry<3>&, const FluidSettings<3>&, int);

}  // namespace valvefsi::fluid
