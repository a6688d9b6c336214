#pragma once
// Small meshes built in C++ for the tests: flat rectangular plates of triangles in the xy-plane,
// circumferential axis along x, normal +z.
#include <cmath>
#include <random>

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

}  // namespace valvefsi::solid::testing
