#pragma once
// Interface surfaces for the mapping tests: a curved (cylindrical) triangulated patch, a tilted
// flat plate, a 2D polyline, and points sampled exactly on their cells.

#include "valvefsi/coupling/interface_mapping.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>
#include <random>

namespace valvefsi::coupling::testing {

// nu x nv grid mapped through `place(u, v)` (u, v in [0, 1]), two triangles per quad.
template <class Place>
InterfaceMesh grid_surface(int nu, int nv, Place place) {
  InterfaceMesh mesh;
  mesh.nodes_per_cell = 3;
  mesh.positions.resize(3, (nu + 1) * (nv + 1));
  for (int j = 0; j <= nv; ++j) {
    for (int i = 0; i <= nu; ++i) mesh.positions.col(j * (nu + 1) + i) = place(double(i) / nu, double(j) / nv);
  }
  mesh.cells.resize(3, 2 * nu * nv);
  int c = 0;
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const int n0 = j * (nu + 1) + i, n1 = n0 + 1, n2 = n0 + nu + 1, n3 = n2 + 1;
      mesh.cells.col(c++) << n0, n1, n3;
      mesh.cells.col(c++) << n0, n3, n2;
    }
  }
  mesh.node_areas = Eigen::VectorXd::Constant(mesh.positions.cols(), 1.0 / (nu * nv));
  return mesh;
}

// A quarter cylinder of radius 12 mm and height 10 mm: curved, so it spans all three directions.
inline InterfaceMesh curved_patch(int nu = 12, int nv = 10) {
  return grid_surface(nu, nv, [](double u, double v) {
    const double angle = 0.5 * std::numbers::pi * u;
    return Eigen::Vector3d(0.012 * std::cos(angle), 0.012 * std::sin(angle), 0.010 * v);
  });
}

// A flat 10 mm x 8 mm plate rotated out of the coordinate planes (tests the polynomial's axis choice).
inline InterfaceMesh tilted_plate(int nu = 10, int nv = 8) {
  const Eigen::Matrix3d rotation = (Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  return grid_surface(nu, nv, [&](double u, double v) {
    return Eigen::Vector3d(rotation * Eigen::Vector3d(0.010 * u, 0.008 * v, 0.0) + Eigen::Vector3d(0.001, -0.002, 0.003));
  });
}

// A 2D leaflet-like arc in the z = 0 plane, cut into segments.
inline InterfaceMesh arc_2d(int segments = 20) {
  InterfaceMesh mesh;
  mesh.nodes_per_cell = 2;
  mesh.positions.resize(3, segments + 1);
  for (int i = 0; i <= segments; ++i) {
    const double angle = 0.8 * double(i) / segments;
    mesh.positions.col(i) << 0.01 * std::sin(angle), 0.01 * (1.0 - std::cos(angle)) + 0.002 * double(i) / segments, 0.0;
  }
  mesh.cells.resize(2, segments);
  for (int i = 0; i < segments; ++i) mesh.cells.col(i) << i, i + 1;
  mesh.node_areas = Eigen::VectorXd::Constant(segments + 1, 0.01 / segments);
  return mesh;
}

// Points drawn uniformly on randomly chosen cells (exactly on the surface).
inline Eigen::Matrix3Xd points_on_cells(const InterfaceMesh& mesh, int count, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_int_distribution<int> pick_cell(0, static_cast<int>(mesh.cells.cols()) - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Eigen::Matrix3Xd points(3, count);
  for (int i = 0; i < count; ++i) {
    const int c = pick_cell(random);
    double a = unit(random), b = mesh.nodes_per_cell == 3 ? unit(random) : 0.0;
    if (a + b > 1.0) { a = 1.0 - a; b = 1.0 - b; }
    Eigen::Vector3d p = (1.0 - a - b) * mesh.positions.col(mesh.cells(0, c)) + a * mesh.positions.col(mesh.cells(1, c));
    if (mesh.nodes_per_cell == 3) p += b * mesh.positions.col(mesh.cells(2, c));
    points.col(i) = p;
  }
  return points;
}

// A linear vector field u(x) = A x + b with O(1) entries (units irrelevant here).
struct LinearField {
  Eigen::Matrix3d a;
  Eigen::Vector3d b;
  Eigen::Matrix3Xd operator()(const Eigen::Matrix3Xd& x) const { return (a * x).colwise() + b; }
};
inline LinearField some_linear_field() {
  LinearField f;
  f.a << 120.0, -35.0, 80.0, 15.0, 60.0, -90.0, -40.0, 25.0, 110.0;
  f.b << 0.3, -0.7, 1.1;
  return f;
}

}  // namespace valvefsi::coupling::testing
