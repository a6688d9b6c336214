#include "valvefsi/fluid/geometry.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <functional>
#include <numbers>
#include <string>
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

namespace {

// The hex-prism lattice's frame: e1 along the rows of the first family, e2 = axis x e1, e3 the axis.
struct HexPrismFrame {
  Vec<3> e1, e2, e3;
  double side, row_spacing;  // a (the triangle side) and a sqrt(3)/2 (rows of one family)
};

inline HexPrismFrame hex_prism_frame(const Vec<3>& axis, const Vec<3>& row, double dp) {
  HexPrismFrame f;
  f.e3 = axis;
  f.e1 = row;
  f.e2 = {axis[1] * row[2] - axis[2] * row[1], axis[2] * row[0] - axis[0] * row[2], axis[0] * row[1] - axis[1] * row[0]};
  // One particle volume dp^3 per point: triangle cell area a^2 sqrt(3)/2 = dp^2.
  f.side = dp * std::sqrt(2.0 / std::sqrt(3.0));
  f.row_spacing = 0.5 * std::sqrt(3.0) * f.side;
  return f;
}

// Lattice point (i, j, k) of the hex prism, relative to the origin: u = a/4 + a i + a j/2 along
// e1, v = (j - 1/2) h along e2, w = (k + 1/2) dp along the axis, which puts the axis halfway
// between rows of the families at 0 and 60 degrees.
inline void for_each_hex_prism_point(const HexPrismFrame& f, const Vec<3>& origin, const Vec<3>& lower, const Vec<3>& upper, double dp,
                                     const std::function<void(const Vec<3>&)>& visit) {
  double range[3][2] = {{1e300, -1e300}, {1e300, -1e300}, {1e300, -1e300}};
  for (int corner = 0; corner < 8; ++corner) {
    Vec<3> rel;
    for (int d = 0; d < 3; ++d) rel[d] = ((corner >> d) & 1 ? upper[d] : lower[d]) - origin[d];
    const double coordinate[3] = {dot<3>(rel, f.e1), dot<3>(rel, f.e2), dot<3>(rel, f.e3)};
    for (int c = 0; c < 3; ++c) {
      range[c][0] = std::min(range[c][0], coordinate[c]);
      range[c][1] = std::max(range[c][1], coordinate[c]);
    }
  }
  const double a = f.side, h = f.row_spacing;
  const long k0 = static_cast<long>(std::floor(range[2][0] / dp)) - 1, k1 = static_cast<long>(std::ceil(range[2][1] / dp)) + 1;
  const long j0 = static_cast<long>(std::floor(range[1][0] / h)) - 1, j1 = static_cast<long>(std::ceil(range[1][1] / h)) + 1;
  for (long k = k0; k <= k1; ++k) {
    const double w = (static_cast<double>(k) + 0.5) * dp;
    for (long j = j0; j <= j1; ++j) {
      const double v = (static_cast<double>(j) - 0.5) * h;
      const double start = 0.25 * a + 0.5 * a * static_cast<double>(j);
      const long i0 = static_cast<long>(std::floor((range[0][0] - start) / a)) - 1;
      const long i1 = static_cast<long>(std::ceil((range[0][1] - start) / a)) + 1;
      for (long i = i0; i <= i1; ++i) {
        const double u = start + a * static_cast<double>(i);
        Vec<3> x;
        bool inside = true;
        for (int d = 0; d < 3; ++d) {
          x[d] = origin[d] + u * f.e1[d] + v * f.e2[d] + w * f.e3[d];
          inside = inside && x[d] >= lower[d] && x[d] < upper[d];
        }
        if (inside) visit(x);
      }
    }
  }
}

// Calls visit(x) for every lattice point in the domain.
template <int D>
void for_each_lattice_point(const SceneGeometry<D>& scene, const FluidSettings<D>& s, const std::function<void(const Vec<D>&)>& visit) {
  const double dp = s.particle_spacing;
  if constexpr (D == 3) {
    if (scene.lattice == FillLattice::hex_prism) {
      const HexPrismFrame f = hex_prism_frame(scene.lattice_axis, scene.lattice_row_direction, dp);
      for_each_hex_prism_point(f, scene.lattice_origin, s.domain_lower, s.domain_upper, dp, visit);
      return;
    }
  }
  if (scene.lattice != FillLattice::cubic) throw std::invalid_argument("fluid fill: the hex-prism lattice is 3D only");
  std::array<long, D> first{}, count{};
  long total = 1;
  for (int d = 0; d < D; ++d) {
    first[d] = static_cast<long>(std::ceil((s.domain_lower[d] - scene.lattice_origin[d]) / dp - 0.5 - 1e-9));
    const long last = static_cast<long>(std::floor((s.domain_upper[d] - scene.lattice_origin[d]) / dp - 0.5 - 1e-9));
    count[d] = std::max(0L, last - first[d] + 1);
    total *= count[d];
  }
  for (long flat = 0; flat < total; ++flat) {
    Vec<D> x;
    long rest = flat;
    for (int d = 0; d < D; ++d) {
      x[d] = scene.lattice_origin[d] + (static_cast<double>(first[d] + rest % count[d]) + 0.5) * dp;
      rest /= count[d];
    }
    visit(x);
  }
}

}  // namespace

template <int D>
std::string fill_lattice_mismatch(const SceneGeometry<D>& scene, const FluidSettings<D>& s) {
  if (scene.lattice == FillLattice::cubic) return {};
  if constexpr (D != 3) {
    return "HEX_PRISM is a 3D lattice (triangular layers stacked along an axis): allowed in 2D only CUBIC";
  } else {
    const double dp = s.particle_spacing;
    const Vec<3>& axis = scene.lattice_axis;
    const Vec<3>& row = scene.lattice_row_direction;
    if (std::abs(dot<3>(axis, axis) - 1.0) > 1e-9) return "lattice_axis is not a unit vector (give a non-zero direction)";
    if (std::abs(dot<3>(row, row) - 1.0) > 1e-9) return "lattice_row_direction is not a unit vector (give a non-zero direction)";
    if (std::abs(dot<3>(axis, row)) > 1e-9)
      return fmt::format("lattice_row_direction makes {:.6g} degrees with lattice_axis: allowed 90 (rows lie in the layers)",
                         std::acos(std::clamp(dot<3>(axis, row), -1.0, 1.0)) * 180.0 / std::numbers::pi);
    const HexPrismFrame f = hex_prism_frame(axis, row, dp);
    const double r3 = 0.5 * std::sqrt(3.0);
    // Normals of the rows at 0, 60 and 120 degrees to e1.
    const std::array<Vec<3>, 3> row_normals = {f.e2,
                                                Vec<3>{r3 * f.e1[0] - 0.5 * f.e2[0], r3 * f.e1[1] - 0.5 * f.e2[1], r3 * f.e1[2] - 0.5 * f.e2[2]},
                                                Vec<3>{r3 * f.e1[0] + 0.5 * f.e2[0], r3 * f.e1[1] + 0.5 * f.e2[1], r3 * f.e1[2] + 0.5 * f.e2[2]}};
    // Lattice point (0, 0) of layer 0 without its axial offset.
    Vec<3> first_point;
    for (int d = 0; d < 3; ++d) first_point[d] = scene.lattice_origin[d] + 0.25 * f.side * f.e1[d] - 0.5 * f.row_spacing * f.e2[d];
    for (std::size_t k = 0; k < s.mirror_planes.size(); ++k) {
      const auto& plane = s.mirror_planes[k];
      const double along_axis = dot<3>(plane.normal, axis);
      Vec<3> rel;
      for (int d = 0; d < 3; ++d) rel[d] = first_point[d] - plane.point[d];
      auto fraction = [](double x) { return x - std::floor(x); };
      if (std::abs(along_axis) > 1.0 - 1e-9) {
        const double layers = fraction(dot<3>(rel, plane.normal) / dp + 0.5);  // layers at (k + 1/2) dp
        if (std::abs(layers - 0.5) > 1e-6)
          return fmt::format("mirror_planes[{}] (normal to the lattice axis) lies {:.4f} dp from a particle layer: allowed "
                             "halfway between layers (0.5 dp); move lattice_origin along the axis",
                             k, std::min(layers, 1.0 - layers));
        continue;
      }
      if (std::abs(along_axis) > 1e-9)
        return fmt::format("mirror_planes[{}] makes {:.6g} degrees with lattice_axis: allowed planes that contain the axis "
                           "(along a row family) or are normal to it",
                           k, 90.0 - std::acos(std::clamp(std::abs(along_axis), 0.0, 1.0)) * 180.0 / std::numbers::pi);
      bool along_rows = false;
      for (const auto& m : row_normals) along_rows = along_rows || std::abs(std::abs(dot<3>(m, plane.normal)) - 1.0) < 1e-9;
      if (!along_rows)
        return fmt::format("mirror_planes[{}] does not run along a row family of the hex-prism lattice (rows at 0, 60 and 120 "
                           "degrees to lattice_row_direction): allowed a plane along one of them (turn lattice_row_direction)",
                           k);
      const double rows = fraction(dot<3>(rel, plane.normal) / f.row_spacing);
      if (std::abs(rows - 0.5) > 1e-6)
        return fmt::format("mirror_planes[{}] lies {:.4f} dp from the nearest row of the hex-prism lattice: allowed halfway "
                           "between rows ({:.4f} dp); the axis through lattice_origin lies halfway between the rows at 0 and "
                           "60 degrees to lattice_row_direction",
                           k, std::min(rows, 1.0 - rows) * f.row_spacing / dp, 0.5 * f.row_spacing / dp);
    }
    return {};
  }
}

template <int D>
Particles<D> fill_particles(const SceneGeometry<D>& scene, const FluidSettings<D>& s, int wall_layers) {
  const double dp = s.particle_spacing;
  if (wall_layers <= 0) wall_layers = static_cast<int>(std::ceil(s.support_radius() / dp - 1e-9));
  const double wall_thickness = wall_layers * dp;
  const LinearMieGruneisen eos{s.rest_density, s.sound_speed};
  if (const std::string why = fill_lattice_mismatch(scene, s); !why.empty()) throw std::invalid_argument("fluid fill: " + why);

  Particles<D> particles;
  const double tiny = 1e-9 * dp;
  for_each_lattice_point<D>(scene, s, [&](const Vec<D>& x) {
    // Beyond a mirror plane live only images. Points closer than 0.4 dp to a plane are left
    // out too: their images would sit almost on them (a plane on a lattice plane keeps its
    // first layer, at dp/2).
    bool mirrored_away = false;
    for (const auto& plane : s.mirror_planes) {
      double distance = 0;
      for (int d = 0; d < D; ++d) distance += (x[d] - plane.point[d]) * plane.normal[d];
      mirrored_away = mirrored_away || distance < 0.4 * dp;
    }
    if (mirrored_away) return;
    // Plates first, then fixed walls, then fluid.
    int plate = -1;
    for (std::size_t k = 0; k < scene.plates.size() && plate < 0; ++k)
      if (scene.plates[k]->depth(x) > tiny) plate = static_cast<int>(k);
    if (plate >= 0) {
      particles.add(x, {}, 0.0f, Kind::wall, static_cast<std::uint16_t>(plate + 1));
      return;
    }
    double wall_depth = 0;
    for (const auto& w : scene.walls) wall_depth = std::max(wall_depth, w->depth(x));
    if (wall_depth > tiny) {
      if (wall_depth < wall_thickness) particles.add(x, {}, 0.0f, Kind::wall, 0);
      return;
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
  });
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
template std::string fill_lattice_mismatch<2>(const SceneGeometry<2>&, const FluidSettings<2>&);
template std::string fill_lattice_mismatch<3>(const SceneGeometry<3>&, const FluidSettings<3>&);
template Particles<2> fill_particles<2>(const SceneGeometry<2>&, const FluidSettings<2>&, int);
template Particles<3> fill_particles<3>(const SceneGeometry<3>&, const FluidSettings<3>&, int);

}  // namespace valvefsi::fluid
