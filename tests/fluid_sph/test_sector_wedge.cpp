// A still 60-degree wedge of fluid between two mirror planes (a valve sector without leaflets),
// inside a tube, periodic along the axis, at the sector's background pressure:
// with the hex-prism fill and the images of images, the kernel sum is near 1 at both mirror
// planes and at the axis, and the fluid stays still; the cubic fill leaves a slab empty along
// the plane at 60 degrees and the single images leave half the neighbourhood of the axis empty,
// and then the fluid does not stay still (issue 6, the sector's start-up loads).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "valvefsi/fluid/fluid_solver.hpp"
#include "valvefsi/fluid/geometry.hpp"
#include "valvefsi/fluid/kernels.hpp"
#include "valvefsi/fluid/mirror_group.hpp"

namespace valvefsi::fluid {
namespace {

constexpr double dp = 0.9e-3;          // the coarse sector's spacing
constexpr double radius = 12 * dp;     // tube radius
constexpr double length = 10 * dp;     // periodic length along the axis (> 3 supports)
const double kSixty = std::numbers::pi / 3.0;

struct Wedge {
  FillLattice lattice;
  bool images_of_images;
};

FluidSolver<3> still_wedge(const Wedge& w) {
  FluidSettings<3> s;
  s.particle_spacing = dp;
  s.rest_density = 1056.0;
  s.dynamic_viscosity = 0.0035;
  s.sound_speed = 145.0;
  s.background_pressure = 10763.1163;  // the sector's 80.73 mmHg
  s.domain_lower = {-5 * dp, -5 * dp, 0.0};
  s.domain_upper = {radius + 5 * dp, radius + 5 * dp, length};
  s.periodic = {false, false, true};
  s.mirror_planes.push_back({{0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}});
  s.mirror_planes.push_back({{0.0, 0.0, 0.0}, {std::sin(kSixty), -std::cos(kSixty), 0.0}});
  s.mirror_images_of_images = w.images_of_images;
  SceneGeometry<3> scene;
  scene.lattice = w.lattice;
  scene.lattice_axis = {0.0, 0.0, 1.0};
  scene.lattice_row_direction = {1.0, 0.0, 0.0};
  scene.walls.push_back(tube_wall<3>({0.0, 0.0, -1.0}, {0.0, 0.0, 1.0}, 2.0, radius));
  scene.fluid.push_back({{-1.0, -1.0, -1.0}, {1.0, 1.0, 1.0}, {}, [](const Vec<3>&) { return 0.0; }});
  return FluidSolver<3>(s, fill_particles(scene, s));
}

// Shepard sum sum_b V_b W(x - x_b) over every particle (fluid, walls, images), averaged over
// points spread over one spacing along the axis.
double kernel_sum(const FluidSolver<3>& solver, double x, double y) {
  const auto& p = solver.particles();
  const CubicSplineKernel<3> kernel(solver.settings().smoothing_length());
  const double volume = dp * dp * dp;
  double total = 0;
  const int samples = 8;
  for (int k = 0; k < samples; ++k) {
    const double z = 0.5 * length + dp * k / samples;
    for (std::size_t b = 0; b < p.size(); ++b) {
      if (p.kind[b] == Kind::lost) continue;
      const double dx = p.position[0][b] - x, dy = p.position[1][b] - y, dz = p.position[2][b] - z;
      total += volume * kernel.value(static_cast<float>(std::sqrt(dx * dx + dy * dy + dz * dz)));
    }
  }
  return total / samples;
}

struct Measured {
  double first_plane, second_plane, axis, inside, max_speed;
  std::size_t lost;
};

Measured measure(const Wedge& w, int steps) {
  FluidSolver<3> solver = still_wedge(w);
  const double r = 0.5 * radius;
  Measured m{};
  m.first_plane = kernel_sum(solver, r, 0.0);
  m.second_plane = kernel_sum(solver, r * std::cos(kSixty), r * std::sin(kSixty));
  m.axis = kernel_sum(solver, 0.0, 0.0);
  m.inside = kernel_sum(solver, r * std::cos(0.5 * kSixty), r * std::sin(0.5 * kSixty));
  // The largest fluid speed over the run (the start-up transient peaks and then oscillates).
  for (int n = 0; n < steps; ++n) {
    solver.step();
    const auto& p = solver.particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.kind[i] != Kind::fluid) continue;
      double v2 = 0;
      for (int d = 0; d < 3; ++d) v2 += static_cast<double>(p.velocity[d][i]) * p.velocity[d][i];
      m.max_speed = std::max(m.max_speed, std::sqrt(v2));
    }
  }
  m.lost = solver.lost_count();
  std::printf("%s fill, %s: kernel sum at plane y = 0 %.4f, plane at 60 deg %.4f, axis %.4f, inside %.4f; "
              "over %d steps (%.3g ms) largest speed %.3g m/s, lost %zu\n",
              w.lattice == FillLattice::hex_prism ? "hex-prism" : "cubic", w.images_of_images ? "images of images" : "single images",
              m.first_plane, m.second_plane, m.axis, m.inside, steps, 1e3 * solver.time(), m.max_speed, m.lost);
  return m;
}

constexpr int kSteps = 300;

TEST(SectorWedge, HexPrismFillWithImagesOfImagesStaysStill) {
  const Measured m = measure({FillLattice::hex_prism, true}, kSteps);
  EXPECT_NEAR(m.first_plane, 1.0, 0.01);
  EXPECT_NEAR(m.second_plane, 1.0, 0.01);
  // The axis lies halfway along a bond of the triangular layers (the only place halfway between
  // rows of both families): its 6 nearest particles form a ring of 0.93 dp with no centre.
  EXPECT_NEAR(m.axis, 1.0, 0.1);
  EXPECT_NEAR(m.inside, 1.0, 0.01);
  // That ring closes in by ~0.02 dp (peak 0.057 m/s measured); single images: 0.46 m/s.
  EXPECT_LT(m.max_speed, 0.1);
  EXPECT_EQ(m.lost, 0u);
}

TEST(SectorWedge, CubicFillLeavesTheSixtyDegreePlaneShort) {
  const Measured m = measure({FillLattice::cubic, true}, kSteps);
  EXPECT_NEAR(m.first_plane, 1.0, 0.01);     // on a lattice plane: fine
  EXPECT_LT(m.second_plane, 0.9);            // the empty slab along the plane at 60 degrees
  EXPECT_GT(m.max_speed, 0.2);
}

TEST(SectorWedge, SingleImagesLeaveTheAxisShort) {
  const Measured m = measure({FillLattice::hex_prism, false}, kSteps);
  EXPECT_NEAR(m.second_plane, 1.0, 0.01);
  EXPECT_LT(m.axis, 0.6);                    // half the neighbourhood of the axis has no image
  EXPECT_GT(m.max_speed, 0.2);
}

TEST(MirrorGroup, SixtyDegreePlanesCloseInSixElements) {
  std::vector<MirrorPlane<3>> planes = {{{0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}},
                                        {{0.0, 0.0, 0.0}, {std::sin(kSixty), -std::cos(kSixty), 0.0}}};
  // Order 6: identity, the two planes' reflections, and 3 compound images.
  EXPECT_EQ(compound_mirror_maps<3>(planes).size(), 3u);
  // Octant: three perpendicular planes, order 8.
  std::vector<MirrorPlane<3>> octant = {{{0, 0, 0}, {1, 0, 0}}, {{0, 0, 0}, {0, 1, 0}}, {{0, 0, 0}, {0, 0, 1}}};
  EXPECT_EQ(compound_mirror_maps<3>(octant).size(), 8u - 4u);
  // Parallel planes only: single images suffice.
  std::vector<MirrorPlane<3>> slab = {{{0, 0, 0}, {0, 1, 0}}, {{0, 1, 0}, {0, -1, 0}}};
  EXPECT_TRUE(compound_mirror_maps<3>(slab).empty());
  // A 50-degree wedge is not 180/n (its 36 images would overlap the fluid); a slab crossed by a
  // third plane never closes.
  const double fifty = 50.0 * std::numbers::pi / 180.0;
  auto refusal = [](const std::vector<MirrorPlane<3>>& planes) -> std::string {
    try {
      compound_mirror_maps<3>(planes);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "not refused";
  };
  const std::string wedge = refusal({{{0, 0, 0}, {0, 1, 0}}, {{0, 0, 0}, {std::sin(fifty), -std::cos(fifty), 0}}});
  EXPECT_NE(wedge.find("wedge of 50 degrees: allowed 180/n"), std::string::npos) << wedge;
  const std::string infinite = refusal({{{0, 0, 0}, {0, 1, 0}}, {{0, 1, 0}, {0, -1, 0}}, {{0, 0, 0}, {1, 0, 0}}});
  EXPECT_NE(infinite.find("more than 48"), std::string::npos) << infinite;
}

TEST(MirrorGroup, SymmetryFactorCountsTheCopiesOfTheWhole) {
  // The factor from a part's flows to the whole's: the group's order.
  EXPECT_EQ(mirror_symmetry_factor<3>({}), 1.0);
  EXPECT_EQ(mirror_symmetry_factor<3>({{{0, 0, 0}, {0, 1, 0}}}), 2.0);
  std::vector<MirrorPlane<3>> sixty = {{{0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}},
                                       {{0.0, 0.0, 0.0}, {std::sin(kSixty), -std::cos(kSixty), 0.0}}};
  EXPECT_EQ(mirror_symmetry_factor<3>(sixty), 6.0);
  std::vector<MirrorPlane<3>> octant = {{{0, 0, 0}, {1, 0, 0}}, {{0, 0, 0}, {0, 1, 0}}, {{0, 0, 0}, {0, 0, 1}}};
  EXPECT_EQ(mirror_symmetry_factor<3>(octant), 8.0);
  // A 30-degree wedge: 12 copies.
  const double thirty = 30.0 * std::numbers::pi / 180.0;
  EXPECT_EQ(mirror_symmetry_factor<3>({{{0, 0, 0}, {0, 1, 0}}, {{0, 0, 0}, {std::sin(thirty), -std::cos(thirty), 0}}}), 12.0);
  // Between parallel mirror walls there is no finite whole.
  EXPECT_EQ(mirror_symmetry_factor<3>({{{0, 0, 0}, {0, 1, 0}}, {{0, 1, 0}, {0, -1, 0}}}), 0.0);
  EXPECT_EQ(mirror_symmetry_factor<2>({{{0, 0}, {1, 0}}, {{0, 0}, {0, 1}}}), 4.0);
}

}  // namespace
}  // namespace valvefsi::fluid
