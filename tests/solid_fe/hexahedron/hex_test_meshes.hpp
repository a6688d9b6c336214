#pragma once
// Brick meshes built in C++ for the hexahedron tests: boxes of nx x ny x nz bricks, material axes
// circumferential = x, radial = y (normal z), node sets for the six faces.
#include <cmath>
#include <random>
#include <string>

#include "valvefsi/solid/mesh.hpp"

namespace valvefsi::solid::testing {

inline std::int64_t box_node(int i, int j, int k, int nx, int ny) {
  return (static_cast<std::int64_t>(k) * (ny + 1) + j) * (nx + 1) + i;
}

// `jitter` moves interior nodes randomly by up to that fraction of a cell (irregular patch meshes).
inline Mesh box_mesh(double lx, double ly, double lz, int nx, int ny, int nz, double jitter = 0.0, unsigned seed = 3) {
  Mesh m;
  m.nodes.resize(3, (nx + 1) * (ny + 1) * (nz + 1));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-jitter, jitter);
  for (int k = 0; k <= nz; ++k) {
    for (int j = 0; j <= ny; ++j) {
      for (int i = 0; i <= nx; ++i) {
        Eigen::Vector3d p(lx * i / nx, ly * j / ny, lz * k / nz);
        if (i > 0 && i < nx && j > 0 && j < ny && k > 0 && k < nz) {
          p += Eigen::Vector3d(u(rng) * lx / nx, u(rng) * ly / ny, u(rng) * lz / nz);
        }
        m.nodes.col(box_node(i, j, k, nx, ny)) = p;
        const std::int64_t n = box_node(i, j, k, nx, ny);
        if (i == 0) m.node_sets["x0"].push_back(n);
        if (i == nx) m.node_sets["x1"].push_back(n);
        if (j == 0) m.node_sets["y0"].push_back(n);
        if (j == ny) m.node_sets["y1"].push_back(n);
        if (k == 0) m.node_sets["z0"].push_back(n);
        if (k == nz) m.node_sets["z1"].push_back(n);
      }
    }
  }
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        m.hexahedra.push_back({box_node(i, j, k, nx, ny), box_node(i + 1, j, k, nx, ny),
                               box_node(i + 1, j + 1, k, nx, ny), box_node(i, j + 1, k, nx, ny),
                               box_node(i, j, k + 1, nx, ny), box_node(i + 1, j, k + 1, nx, ny),
                               box_node(i + 1, j + 1, k + 1, nx, ny), box_node(i, j + 1, k + 1, nx, ny)});
      }
    }
  }
  const auto h = static_cast<Eigen::Index>(m.hexahedra.size());
  m.hexahedron_circumferential = Eigen::Vector3d::UnitX().replicate(1, h);
  m.hexahedron_radial = Eigen::Vector3d::UnitY().replicate(1, h);
  return m;
}

}  // namespace valvefsi::solid::testing
