#include "valvefsi/fluid/thin_wall/scenes_3d.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

namespace valvefsi::fluid::thin_wall {

namespace {
// A disk in a plane x = const: every triangle's normal along +x, zero thickness (the scenes'
// plates are sheets).
ImmersedSurfaceGeometry<3> oriented_along_plus_x(ImmersedSurfaceGeometry<3> g) {
  for (std::size_t t = 0; t < g.cells.size(); t += 3) {
    const Vec3& a = g.nodes[g.cells[t]];
    const Vec3& b = g.nodes[g.cells[t + 1]];
    const Vec3& c = g.nodes[g.cells[t + 2]];
    const double nx = (b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]);
    if (nx < 0) std::swap(g.cells[t + 1], g.cells[t + 2]);
  }
  g.node_thickness.assign(g.nodes.size(), 0.0);
  return g;
}
}  // namespace

ImmersedSurfaceGeometry<3> rectangle_mesh(const Vec3& origin, const Vec3& u, const Vec3& v, int nu, int nv) {
  ImmersedSurfaceGeometry<3> g;
  g.nodes_per_cell = 3;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      const double s = static_cast<double>(i) / nu, t = static_cast<double>(j) / nv;
      g.nodes.push_back({origin[0] + s * u[0] + t * v[0], origin[1] + s * u[1] + t * v[1], origin[2] + s * u[2] + t * v[2]});
    }
  auto node = [nu](int i, int j) { return static_cast<std::uint32_t>(j * (nu + 1) + i); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const std::uint32_t a = node(i, j), b = node(i + 1, j), c = node(i + 1, j + 1), d = node(i, j + 1);
      g.cells.insert(g.cells.end(), {a, b, c, a, c, d});
    }
  g.node_thickness.assign(g.nodes.size(), 0.0);
  return g;
}

ImmersedSurfaceGeometry<3> disk_mesh(const Vec3& centre, double radius, double spacing) {
  ImmersedSurfaceGeometry<3> g;
  g.nodes_per_cell = 3;
  const int rings = std::max(1, static_cast<int>(std::lround(radius / spacing)));
  g.nodes.push_back(centre);
  std::vector<std::uint32_t> ring_start{0};
  for (int k = 1; k <= rings; ++k) {
    ring_start.push_back(static_cast<std::uint32_t>(g.nodes.size()));
    const double r = radius * k / rings;
    for (int j = 0; j < 6 * k; ++j) {
      const double phi = 2.0 * std::numbers::pi * j / (6 * k);
      g.nodes.push_back({centre[0], centre[1] + r * std::cos(phi), centre[2] + r * std::sin(phi)});
    }
  }
  // Between ring k - 1 and ring k: advance along whichever ring's next node comes first in angle.
  for (int k = 1; k <= rings; ++k) {
    const int n_in = k == 1 ? 1 : 6 * (k - 1), n_out = 6 * k;
    auto inner = [&](int j) { return k == 1 ? 0u : ring_start[static_cast<std::size_t>(k - 1)] + static_cast<std::uint32_t>(j % n_in); };
    auto outer = [&](int j) { return ring_start[static_cast<std::size_t>(k)] + static_cast<std::uint32_t>(j % n_out); };
    int i = 0, o = 0;
    while (i < (k == 1 ? 0 : n_in) || o < n_out) {
      const double next_in = k == 1 ? 2.0 : static_cast<double>(i + 1) / n_in;
      const double next_out = static_cast<double>(o + 1) / n_out;
      if (o < n_out && (next_out <= next_in || i >= n_in)) {
        g.cells.insert(g.cells.end(), {inner(i), outer(o), outer(o + 1)});
        ++o;
      } else {
        g.cells.insert(g.cells.end(), {inner(i), outer(o), inner(i + 1)});
        ++i;
      }
    }
  }
  return oriented_along_plus_x(std::move(g));
}

ImmersedSurfaceGeometry<3> quarter_disk_mesh(const Vec3& centre, double radius, double spacing) {
  ImmersedSurfaceGeometry<3> g;
  g.nodes_per_cell = 3;
  const int rings = std::max(1, static_cast<int>(std::lround(radius / spacing)));
  g.nodes.push_back(centre);
  std::vector<std::uint32_t> ring_start{0};
  for (int k = 1; k <= rings; ++k) {
    ring_start.push_back(static_cast<std::uint32_t>(g.nodes.size()));
    const double r = radius * k / rings;
    for (int j = 0; j <= k; ++j) {
      const double phi = 0.5 * std::numbers::pi * j / k;
      g.nodes.push_back({centre[0], centre[1] + r * std::cos(phi), centre[2] + r * std::sin(phi)});
    }
  }
  // Between ring k - 1 (k nodes, the centre for k = 1) and ring k (k + 1 nodes): advance along
  // whichever ring's next node comes first in angle.
  for (int k = 1; k <= rings; ++k) {
    const int n_in = k, n_out = k + 1;
    auto inner = [&](int j) { return ring_start[static_cast<std::size_t>(k - 1)] + static_cast<std::uint32_t>(k == 1 ? 0 : j); };
    auto outer = [&](int j) { return ring_start[static_cast<std::size_t>(k)] + static_cast<std::uint32_t>(j); };
    auto angle_in = [&](int j) { return k == 1 ? 2.0 : static_cast<double>(j) / (k - 1); };
    auto angle_out = [&](int j) { return static_cast<double>(j) / k; };
    int i = 0, o = 0;
    while (i < n_in - 1 || o < n_out - 1) {
      if (o < n_out - 1 && (i >= n_in - 1 || angle_out(o + 1) <= angle_in(i + 1))) {
        g.cells.insert(g.cells.end(), {inner(i), outer(o), outer(o + 1)});
        ++o;
      } else {
        g.cells.insert(g.cells.end(), {inner(i), outer(o), inner(i + 1)});
        ++i;
      }
    }
  }
  return oriented_along_plus_x(std::move(g));
}

ThinWallCase3D two_level_tank_3d(double dp, double left_level, double right_level, double width, double gap, bool mirror) {
  ThinWallCase3D c;
  auto& s = c.fluid;
  const double L = 0.5, top = std::max(left_level, right_level);
  s.particle_spacing = dp;
  s.rest_density = 1000.0;
  s.dynamic_viscosity = 1e-3;
  s.artificial_viscosity = 0.02;  // damps the start-up's acoustic transient
  s.gravity = {0.0, 0.0, -9.81};
  s.sound_speed = 15.0 * std::sqrt(9.81 * top);
  const double margin = mirror ? 4.0 * dp : 0.1;
  s.domain_lower = {-0.1, -margin, -0.1};
  s.domain_upper = {L + 0.1, width + margin, 1.2 * top + 0.1};
  if (mirror) {
    c.scene.walls.push_back(container_box<3>({0.0, -1e9, 0.0}, {L, 1e9, 1e9}));
    s.mirror_planes.push_back({{0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}});
    s.mirror_planes.push_back({{0.0, width, 0.0}, {0.0, -1.0, 0.0}});
  } else {
    c.scene.walls.push_back(container_box<3>({0.0, 0.0, 0.0}, {L, width, 1e9}));
  }
  c.scene.fluid.push_back({{0.0, 0.0, 0.0}, {L / 2, width, left_level}, {}, {}});
  c.scene.fluid.push_back({{L / 2, 0.0, 0.0}, {L, width, right_level}, {}, {}});
  const double y0 = mirror ? 0.0 : -3.0 * dp, y1 = mirror ? width : width + 3.0 * dp;
  const double z0 = gap > 0 ? gap : -3.0 * dp, z1 = 1.2 * top;
  c.surface = rectangle_mesh({L / 2, y0, z0}, {0.0, y1 - y0, 0.0}, {0.0, 0.0, z1 - z0},
                             std::max(1, static_cast<int>(std::lround((y1 - y0) / dp))),
                             std::max(1, static_cast<int>(std::lround((z1 - z0) / dp))));
  return c;
}

ThinWallCase3D oscillating_disk_box(double dp, const OscillatingDisk& disk) {
  ThinWallCase3D c;
  auto& s = c.fluid;
  s.particle_spacing = dp;
  s.rest_density = 1000.0;
  s.dynamic_viscosity = disk.viscosity;
  const double omega = 2.0 * std::numbers::pi / disk.period;
  const double speed = disk.amplitude * omega;
  s.sound_speed = std::max(20.0 * speed, 40.0 * disk.box / disk.period);
  s.shifting = 1.0;
  const double L = disk.box;
  if (disk.quarter) {
    // Walls on the far faces only; the planes y = 0 and z = 0 mirror the rest (and each
    // other's images: the axis x is the rotation by pi about it).
    s.domain_lower = {-0.7 * L, -4.0 * dp, -4.0 * dp};
    s.domain_upper = {0.7 * L, 0.7 * L, 0.7 * L};
    s.mirror_planes.push_back({{0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}});
    s.mirror_planes.push_back({{0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}});
    c.scene.walls.push_back(container_box<3>({-L / 2, -1e9, -1e9}, {L / 2, L / 2, L / 2}));
    c.scene.fluid.push_back({{-L / 2, 0.0, 0.0}, {L / 2, L / 2, L / 2}, {}, [](const Vec<3>&) { return 0.0; }});
    c.surface = quarter_disk_mesh({-disk.amplitude, 0.0, 0.0}, disk.radius, dp);
  } else {
    s.domain_lower = {-0.7 * L, -0.7 * L, -0.7 * L};
    s.domain_upper = {0.7 * L, 0.7 * L, 0.7 * L};
    c.scene.walls.push_back(container_box<3>({-L / 2, -L / 2, -L / 2}, {L / 2, L / 2, L / 2}));
    c.scene.fluid.push_back({{-L / 2, -L / 2, -L / 2}, {L / 2, L / 2, L / 2}, {}, [](const Vec<3>&) { return 0.0; }});
    c.surface = disk_mesh({-disk.amplitude, 0.0, 0.0}, disk.radius, dp);
  }
  const std::vector<Vec3> rest = c.surface.nodes;
  const double A = disk.amplitude;
  c.motion = [rest, A, omega](double t, std::vector<Vec3>& x, std::vector<Vec3>& v) {
    // X = -A cos(wt): starts at rest, centred after the first period.
    x = rest;
    v.assign(rest.size(), Vec3{A * omega * std::sin(omega * t), 0.0, 0.0});
    for (auto& p : x) p[0] = -A * std::cos(omega * t);
  };
  return c;
}

ThinWallCase3D rocking_flap_box(double dp, const RockingFlap& flap) {
  ThinWallCase3D c;
  auto& s = c.fluid;
  s.particle_spacing = dp;
  s.rest_density = 1000.0;
  s.dynamic_viscosity = 1e-3;
  const double tip_speed = flap.max_angle * std::numbers::pi / flap.period * flap.height;
  s.sound_speed = std::max(20.0 * tip_speed, 40.0 * flap.box_length / flap.period);
  s.shifting = 1.0;
  const double L = flap.box_length, W = flap.width, H = flap.box_height;
  s.domain_lower = {-L / 2 - 0.1, -0.1, -0.1};
  s.domain_upper = {L / 2 + 0.1, W + 0.1, H + 0.1};
  c.scene.walls.push_back(container_box<3>({-L / 2, 0.0, 0.0}, {L / 2, W, H}));
  c.scene.fluid.push_back({{-L / 2, 0.0, 0.0}, {L / 2, W, H}, {}, [](const Vec<3>&) { return 0.0; }});
  const double bottom = -3.0 * dp;
  c.surface = rectangle_mesh({0.0, -3.0 * dp, bottom}, {0.0, W + 6.0 * dp, 0.0}, {0.0, 0.0, flap.height - bottom},
                             static_cast<int>(std::lround((W + 6.0 * dp) / dp)),
                             static_cast<int>(std::lround((flap.height - bottom) / dp)));
  const std::vector<Vec3> rest = c.surface.nodes;
  c.motion = [rest, flap](double t, std::vector<Vec3>& x, std::vector<Vec3>& v) {
    // Rotation about the y axis through the floor line (x = 0, z = 0): a point at height z0
    // goes to (z0 sin theta, y, z0 cos theta).
    const double w = std::numbers::pi / flap.period;
    const double sn = std::sin(w * t);
    const double theta = flap.max_angle * sn * sn, rate = flap.max_angle * 2.0 * sn * std::cos(w * t) * w;
    x.resize(rest.size());
    v.resize(rest.size());
    for (std::size_t k = 0; k < rest.size(); ++k) {
      const double z0 = rest[k][2];
      x[k] = {z0 * std::sin(theta), rest[k][1], z0 * std::cos(theta)};
      v[k] = {z0 * std::cos(theta) * rate, 0.0, -z0 * std::sin(theta) * rate};
    }
  };
  return c;
}

}  // namespace valvefsi::fluid::thin_wall
