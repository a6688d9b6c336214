#pragma once
// Small meshes built in C++ for the tests: flat rectangular plates of triangles in the xy-plane,
// circumferential axis along x, normal +z.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "valvefsi/solid/explicit_solver.hpp"
#include "valvefsi/solid/mesh.hpp"

namespace valvefsi::solid::testing {

inline std::int64_t grid_node(int i, int j, int nx) { return static_cast<std::int64_t>(j) * (nx + 1) + i; }

// lx x ly plate, nx x ny cells each split into two triangles; `crossed` alternates the diagonal.
// `jitter` moves interior nodes randomly by that fraction of a cell (irregular patch meshes).
inline Mesh rectangular_plate(double lx, double ly, int nx, int ny, double thickness, bool crossed = false,
                              double jitter = 0.0, unsigned seed = 7) {
  Mesh m;
  m.nodes.resize(3, (nx + 1) * (ny + 1));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-jitter, jitter);
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      double x = lx * i / nx, y = ly * j / ny;
      if (i > 0 && i < nx && j > 0 && j < ny) {
        x += u(rng) * lx / nx;
        y += u(rng) * ly / ny;
      }
      m.nodes.col(grid_node(i, j, nx)) = Eigen::Vector3d(x, y, 0.0);
    }
  }
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const auto n00 = grid_node(i, j, nx), n10 = grid_node(i + 1, j, nx);
      const auto n01 = grid_node(i, j + 1, nx), n11 = grid_node(i + 1, j + 1, nx);
      if (crossed && (i + j) % 2 == 1) {
        m.triangles.push_back({n00, n10, n01});
        m.triangles.push_back({n10, n11, n01});
      } else {
        m.triangles.push_back({n00, n10, n11});
        m.triangles.push_back({n00, n11, n01});
      }
    }
  }
  const auto t = static_cast<Eigen::Index>(m.triangles.size());
  m.triangle_thickness.assign(m.triangles.size(), thickness);
  m.triangle_circumferential = Eigen::Vector3d::UnitX().replicate(1, t);
  m.triangle_radial = Eigen::Vector3d::UnitY().replicate(1, t);
  for (int j = 0; j <= ny; ++j) {
    m.node_sets["left"].push_back(grid_node(0, j, nx));
    m.node_sets["right"].push_back(grid_node(nx, j, nx));
  }
  for (int i = 0; i <= nx; ++i) {
    m.node_sets["bottom"].push_back(grid_node(i, 0, nx));
    m.node_sets["top"].push_back(grid_node(i, ny, nx));
  }
  return m;
}

// Two 6 x 4 mm sheets (leaflets 0 and 1) of nx x ny cells, the upper one shifted in-plane by a fraction of a cell (its nodes meet the
// lower one's triangle faces, edges and corners) and lifted by `lift`; left and right edges held.
struct TwoSheets {
  Mesh mesh;
  std::vector<int> surface;                 // 0 lower, 1 upper
  std::vector<std::int64_t> upper_elements;
  std::vector<std::int64_t> fixed;
};

inline TwoSheets two_sheets(double lift, int nx, int ny, double thickness = 0.25e-3) {
  const Mesh lower = testing::rectangular_plate(6e-3, 4e-3, nx, ny, thickness);
  Mesh upper = testing::rectangular_plate(6e-3, 4e-3, nx, ny, thickness, true);
  upper.nodes.row(0).array() += 0.23e-3;
  upper.nodes.row(1).array() += 0.17e-3;
  upper.nodes.row(2).array() += lift;
  TwoSheets s;
  Mesh& m = s.mesh;
  const Eigen::Index n = lower.num_nodes();
  m.nodes.resize(3, 2 * n);
  m.nodes << lower.nodes, upper.nodes;
  m.triangles = lower.triangles;
  for (auto t : upper.triangles) {
    for (auto& a : t) a += n;
    m.triangles.push_back(t);
  }
  m.triangle_thickness.assign(m.triangles.size(), thickness);
  const auto t = static_cast<Eigen::Index>(m.triangles.size());
  m.triangle_circumferential = Eigen::Vector3d::UnitX().replicate(1, t);
  m.triangle_radial = Eigen::Vector3d::UnitY().replicate(1, t);
  s.surface.assign(static_cast<std::size_t>(2 * n), 0);
  std::fill(s.surface.begin() + n, s.surface.end(), 1);
  for (std::int64_t e = lower.num_triangles(); e < t; ++e) s.upper_elements.push_back(e);
  for (const char* side : {"left", "right"}) {
    for (const auto a : lower.node_sets.at(side)) {
      s.fixed.push_back(a);
      s.fixed.push_back(a + n);
    }
  }
  return s;
}

// The pressed flap's step control (docs/solid_fe.md, "The pressed flap"): calibration every 2000
// steps, growth 0.2 % per step, look-ahead 2 steps, mass damping 300/s (it settles in ~25 ms).
inline SolverOptions pressed_flap_options() {
  SolverOptions o;
  o.time_step_calibration_interval = 2000;
  o.max_time_step_growth = 0.002;
  o.time_step_look_ahead = 2.0;
  o.mass_damping_per_s = 300.0;
  return o;
}

// 2D strip leaflets (docs/mesh-format.md, "2D strips"): each polyline (x-y, attached end first)
// extruded along +z by `depth`; front nodes (z = 0) leaflet after leaflet, then the back nodes in
// the same order; two triangles per segment with normal z x (along the polyline).
inline Mesh strip_mesh(const std::vector<std::vector<Eigen::Vector2d>>& leaflets, double depth, double thickness) {
  Mesh m;
  std::int64_t n = 0;
  for (const auto& l : leaflets) n += static_cast<std::int64_t>(l.size());
  m.nodes.resize(3, 2 * n);
  std::int64_t first = 0;
  std::vector<Eigen::Vector3d> circumferential, radial;
  for (std::size_t k = 0; k < leaflets.size(); ++k) {
    const auto& l = leaflets[k];
    const auto count = static_cast<std::int64_t>(l.size());
    for (std::int64_t i = 0; i < count; ++i) {
      m.nodes.col(first + i) = Eigen::Vector3d(l[static_cast<std::size_t>(i)].x(), l[static_cast<std::size_t>(i)].y(), 0.0);
      m.nodes.col(n + first + i) = Eigen::Vector3d(l[static_cast<std::size_t>(i)].x(), l[static_cast<std::size_t>(i)].y(), depth);
      m.node_sets["strip_front"].push_back(first + i);
      m.node_sets["strip_back"].push_back(n + first + i);
      m.node_sets["leaflet_" + std::to_string(k)].push_back(first + i);
      m.node_sets["leaflet_" + std::to_string(k)].push_back(n + first + i);
    }
    for (std::int64_t i = 0; i + 1 < count; ++i) {
      const std::int64_t f0 = first + i, f1 = f0 + 1, b0 = n + f0, b1 = n + f1;
      m.triangles.push_back({f0, b0, b1});
      m.triangles.push_back({f0, b1, f1});
      const Eigen::Vector2d s = (l[static_cast<std::size_t>(i + 1)] - l[static_cast<std::size_t>(i)]).normalized();
      for (int t = 0; t < 2; ++t) {
        circumferential.push_back(Eigen::Vector3d::UnitZ());
        radial.push_back(Eigen::Vector3d(s.x(), s.y(), 0.0));
      }
    }
    m.node_sets["attachment"].push_back(first);
    m.node_sets["attachment"].push_back(n + first);
    m.node_sets["free_edge"].push_back(first + count - 1);
    m.node_sets["free_edge"].push_back(n + first + count - 1);
    m.node_sets["free_edge_midpoints"].push_back(first + count - 1);
    first += count;
  }
  m.triangle_thickness.assign(m.triangles.size(), thickness);
  m.triangle_circumferential.resize(3, static_cast<Eigen::Index>(circumferential.size()));
  m.triangle_radial.resize(3, static_cast<Eigen::Index>(radial.size()));
  for (std::size_t t = 0; t < circumferential.size(); ++t) {
    m.triangle_circumferential.col(static_cast<Eigen::Index>(t)) = circumferential[t];
    m.triangle_radial.col(static_cast<Eigen::Index>(t)) = radial[t];
  }
  return m;
}

// A straight polyline of `segments` segments from `start` along `direction` (unit) over `length`.
inline std::vector<Eigen::Vector2d> straight_polyline(Eigen::Vector2d start, Eigen::Vector2d direction, double length,
                                                      int segments) {
  std::vector<Eigen::Vector2d> p;
  for (int i = 0; i <= segments; ++i) p.push_back(start + direction * (length * i / segments));
  return p;
}

}  // namespace valvefsi::solid::testing
