// Mirror symmetry planes:
// (1) plane Poiseuille start-up (Morris et al. 1997) in the full channel 0 < y < L and in its
//     lower half with a mirror plane at y = L/2 give the same velocity profile;
// (2) a water column whose right side is a mirror plane tilted 30 degrees from the vertical
//     holds the hydrostatic pressure rho g (H - y), as well next to the plane as far from it,
//     and no particle ends a step beyond the plane.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <numbers>

#include "valvefsi/fluid/fluid_solver.hpp"
#include "valvefsi/fluid/geometry.hpp"
#include "valvefsi/fluid/output.hpp"
#include "valvefsi/fluid/probes.hpp"

#include <hdf5.h>

#include <filesystem>

namespace valvefsi::fluid {
namespace {

constexpr double L = 1e-3, nu = 1e-6, rho = 1000.0, F = 2e-4;

// Mean u_x of the fluid in each of `layers` horizontal layers of height dp from y = 0.
std::vector<double> layer_profile(const FluidSolver<2>& solver, int layers) {
  const double dp = solver.settings().particle_spacing;
  std::vector<double> sum(layers, 0.0), count(layers, 0.0);
  const auto& p = solver.particles();
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.kind[i] != Kind::fluid) continue;
    const int k = static_cast<int>(std::floor(p.position[1][i] / dp));
    if (k < 0 || k >= layers) continue;
    sum[k] += p.velocity[0][i];
    count[k] += 1;
  }
  for (int k = 0; k < layers; ++k) sum[k] /= std::max(count[k], 1.0);
  return sum;
}

FluidSolver<2> poiseuille(int cells_across, bool half) {
  FluidSettings<2> s;
  s.particle_spacing = L / cells_across;
  s.rest_density = rho;
  s.dynamic_viscosity = rho * nu;
  s.gravity = {F, 0.0};
  s.density_diffusion = 0.0;
  s.sound_speed = 500 * F * L * L / (8 * nu);
  const double length = s.particle_spacing * std::ceil(3.0 * s.support_radius() / s.particle_spacing);
  s.domain_lower = {0.0, -0.5 * L};
  s.domain_upper = {length, 1.5 * L};
  s.periodic = {true, false};
  SceneGeometry<2> scene;
  scene.walls.push_back(half_space<2>({0.0, 0.0}, {0.0, 1.0}));
  if (half) {
    s.mirror_planes.push_back({{0.0, 0.5 * L}, {0.0, -1.0}});
  } else {
    scene.walls.push_back(half_space<2>({0.0, L}, {0.0, -1.0}));
  }
  scene.fluid.push_back({{0.0, 0.0}, {length, L}, {}, [](const Vec<2>&) { return 0.0; }});
  return FluidSolver<2>(s, fill_particles(scene, s));
}

TEST(MirrorPlanes, HalfChannelWithMirrorMatchesFullChannel) {
  const int cells = 20;
  FluidSolver<2> full = poiseuille(cells, false);
  FluidSolver<2> half = poiseuille(cells, true);
  EXPECT_EQ(2 * half.particles().count(Kind::fluid), full.particles().count(Kind::fluid));
  EXPECT_GT(half.particles().count(Kind::mirror_fluid), 0u);
  full.advance_to(0.2);
  half.advance_to(0.2);
  const auto a = layer_profile(full, cells / 2);
  const auto b = layer_profile(half, cells / 2);
  double worst = 0, peak = 0;
  for (int k = 0; k < cells / 2; ++k) {
    worst = std::max(worst, std::abs(a[k] - b[k]));
    peak = std::max(peak, std::abs(a[k]));
  }
  std::printf("Poiseuille t = 0.2 s: half + mirror vs full channel, largest layer difference %.3e of %.3e m/s\n", worst, peak);
  EXPECT_GT(peak, 0.5 * F * L * L / (8 * nu));  // the flow has started: > half the steady centreline speed
  EXPECT_LT(worst, 1e-3 * peak);
  EXPECT_EQ(half.lost_count(), 0u);

  // Snapshots hold the particles, not their images.
  const auto dir = std::filesystem::temp_directory_path() / ("fluid_mirror_snapshot_" + std::to_string(::getpid()));
  {
    SnapshotWriter<2> writer(dir);
    writer.write(half);
  }
  const hid_t file = H5Fopen((dir / "fluid_particles.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  const hid_t data = H5Dopen2(file, "snapshot_000000/kind", H5P_DEFAULT);
  const hid_t space = H5Dget_space(data);
  hsize_t rows[2] = {0, 0};
  H5Sget_simple_extent_dims(space, rows, nullptr);
  H5Sclose(space);
  H5Dclose(data);
  H5Fclose(file);
  std::filesystem::remove_all(dir);
  const auto& p = half.particles();
  EXPECT_EQ(rows[0], p.count(Kind::fluid) + p.count(Kind::wall));
  EXPECT_LT(rows[0], p.size());
}

TEST(MirrorPlanes, TiltedMirrorHoldsHydrostaticColumn) {
  const double H = 0.5, g = 9.81, dp = 0.025;
  FluidSettings<2> s;
  s.particle_spacing = dp;
  s.kernel = KernelType::wendland_c2;
  s.rest_density = rho;
  s.dynamic_viscosity = 1e-3;
  s.artificial_viscosity = 0.02;
  s.gravity = {0.0, -g};
  s.sound_speed = 20.0 * std::sqrt(g * H);
  s.domain_lower = {-0.3, -0.3};
  s.domain_upper = {1.6, 1.5};
  // The plane through (0.7, 0), 30 degrees from the vertical, leaning right; fluid on its left.
  const double angle = std::numbers::pi / 6.0;
  const MirrorPlane<2> plane{{0.7, 0.0}, {-std::cos(angle), std::sin(angle)}};
  s.mirror_planes.push_back(plane);
  SceneGeometry<2> scene;
  scene.walls.push_back(container_box<2>({0.0, 0.0}, {1.1, 1e9}));
  scene.fluid.push_back({{0.0, 0.0}, {1.1, H}, {}, {}});
  FluidSolver<2> solver(s, fill_particles(scene, s));
  solver.advance_to(1.5);

  auto distance = [&](const Vec<2>& x) { return (x[0] - plane.point[0]) * plane.normal[0] + (x[1] - plane.point[1]) * plane.normal[1]; };
  double worst = 0;
  for (const Vec<2>& x : {Vec<2>{0.3, 0.1}, Vec<2>{0.3, 0.3}, Vec<2>{0.68, 0.1}, Vec<2>{0.75, 0.2}}) {
    const double p = pressure_at<2>(solver, x);
    const double expected = rho * g * (H - x[1]);
    std::printf("tilted mirror: p(%.2f, %.2f) = %.1f Pa, hydrostatic %.1f Pa (%+.2f %% of rho g H); %.3f m from the plane\n", x[0],
                x[1], p, expected, 100.0 * (p - expected) / (rho * g * H), distance(x));
    worst = std::max(worst, std::abs(p - expected) / (rho * g * H));
  }
  EXPECT_LT(worst, 0.04);
  // At equal depth, next to the plane and far from it: the plane adds no error of its own.
  const double near_plane = pressure_at<2>(solver, {0.68, 0.1}), far = pressure_at<2>(solver, {0.3, 0.1});
  EXPECT_LT(std::abs(near_plane - far), 0.015 * rho * g * H);
  const auto& p = solver.particles();
  std::size_t across = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.kind[i] == Kind::fluid && distance({p.position[0][i], p.position[1][i]}) < 0) ++across;
  EXPECT_EQ(across, 0u);
  EXPECT_EQ(solver.lost_count(), 0u);
}

}  // namespace
}  // namespace valvefsi::fluid
