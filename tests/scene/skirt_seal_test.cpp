// The sector FSI cases' scalloped skirt seals on the fluid's own fill (hex-prism lattice): the
// case file is filled by fluid_sph's code and no blood lies inside the skirt wall, none touches a
// wall particle, and no blood inside the stent sees blood in the sinus within a kernel support
// below the attachment line (docs/valve-scene.md, "Tube"; scripts/valve_scene/tube_case.py).
// With the cubic lattice's columns on the hex lattice, this fill left 33 blood particles inside
// the skirt and 294 inside-sinus pairs within a support (coarse sector, measured with fluid_sph).
// The leaflets' attachment line itself must lie inside the wall (its nearest particle a wall
// particle): with the skirt starting at the stent radius and its tops below the line, the line
// was up to 1.13 dp from a wall particle (0.72 dp of blood in between at the leaflet's centre)
// and the closed valve's 97 mmHg pushed blood from the sinus under the leaflets' base at ~5 m/s
// (docs/fsi-3d.md, "The leak under the leaflets' base").
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/fluid/case_setup.hpp"
#include "valvefsi/fluid/geometry.hpp"

namespace {

namespace fs = std::filesystem;
using valvefsi::fluid::Kind;

// The generic size-23 valve (docs/valve-scene.md, "Valve geometry"): stent radius, commissure
// height, tab length and the coaptation gap that sets the leaflet's half angle.
constexpr double kStentRadius = 11.5e-3;
constexpr double kCommissureHeight = 12.0e-3;
constexpr double kTabHeight = 5.0e-3;
constexpr double kCoaptationGap = 0.5e-3;

// z of the attachment line at an azimuth of the sector (0 = leaflet centre); the commissure tab
// top between the leaflet's tab and its neighbour's.
double attachment_height(double azimuth) {
  const double half_angle = std::numbers::pi / 3.0 - std::asin(kCoaptationGap / (2.0 * kStentRadius));
  const double s = std::abs(azimuth) / half_angle;
  if (s > 1.0) return kCommissureHeight;
  return (kCommissureHeight - kTabHeight) * (1.0 - std::cos(0.5 * std::numbers::pi * s));
}

struct Point {
  double x, y, z;
  double r() const { return std::hypot(x, y); }
  double azimuth() const { return std::atan2(y, x); }
};

double distance(const Point& a, const Point& b) { return std::sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z)); }

struct SealCount {
  double dp = 0, support = 0;
  int fluid_in_skirt = 0;          // blood at R <= r < R + 3 dp under the attachment line
  int fluid_touching_wall = 0;     // blood within 0.5 dp of a wall particle near the skirt
  int pairs_across = 0;            // inside-stent and sinus blood within a support, under the attachment line
  double closest_across = 1e300;   // in dp
  int skirt_walls = 0;             // wall particles of the skirt band above the annulus plane
  int attachment_samples = 0;      // points of the attachment line (scallop and commissure tab edge)
  int attachment_open = 0;         // of them, those whose nearest particle is blood
  double attachment_farthest_wall = 0;  // largest distance from the line to its nearest wall particle, in dp
};

// The attachment line of the sector's leaflet: the scallop from the leaflet centre to the
// commissure, then the tab's edge straight up to the commissure top.
std::vector<Point> attachment_line() {
  const double half_angle = std::numbers::pi / 3.0 - std::asin(kCoaptationGap / (2.0 * kStentRadius));
  std::vector<Point> line;
  for (int k = 0; k <= 400; ++k) {
    const double a = half_angle * k / 400.0;
    line.push_back({kStentRadius * std::cos(a), kStentRadius * std::sin(a), attachment_height(a)});
  }
  const double tab_bottom = attachment_height(half_angle);
  for (int k = 1; k <= 100; ++k)
    line.push_back({kStentRadius * std::cos(half_angle), kStentRadius * std::sin(half_angle),
                    tab_bottom + (kCommissureHeight - tab_bottom) * k / 100.0});
  return line;
}

SealCount count_seal(const fs::path& file) {
  const valvefsi::cases::Case c = valvefsi::load_case(file);
  const auto setup = valvefsi::fluid::fluid_setup_from_case<3>(c, file);
  EXPECT_EQ(setup.scene.lattice, valvefsi::fluid::FillLattice::hex_prism) << file;
  const auto particles = valvefsi::fluid::fill_particles(setup.scene, setup.settings, setup.wall_layers);
  SealCount n;
  n.dp = setup.settings.particle_spacing;
  n.support = setup.settings.support_radius();
  const double dp = n.dp, R = kStentRadius;
  std::vector<Point> fluid_near, walls_near;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const Point p{particles.position[0][i], particles.position[1][i], particles.position[2][i]};
    // the skirt's neighbourhood: the ring's top layers to above the commissure tops
    if (p.z < -2.0 * n.support || p.z > kCommissureHeight + n.support || std::abs(p.r() - R) > R) continue;
    if (particles.kind[i] == Kind::fluid) fluid_near.push_back(p);
    if (particles.kind[i] == Kind::wall) {
      walls_near.push_back(p);
      if (p.z > 0 && p.r() >= R && p.r() < R + 3 * dp) ++n.skirt_walls;
    }
  }
  for (const Point& a : attachment_line()) {
    double nearest_wall = 1e300, nearest_fluid = 1e300;
    for (const Point& w : walls_near) nearest_wall = std::min(nearest_wall, distance(a, w));
    for (const Point& f : fluid_near) nearest_fluid = std::min(nearest_fluid, distance(a, f));
    ++n.attachment_samples;
    if (nearest_fluid < nearest_wall) ++n.attachment_open;
    n.attachment_farthest_wall = std::max(n.attachment_farthest_wall, nearest_wall / dp);
  }
  std::vector<Point> inside, sinus;
  for (const Point& p : fluid_near) {
    const double top = attachment_height(p.azimuth()) - 0.5 * dp;
    if (p.z > 0 && p.z < top && p.r() >= R && p.r() < R + 3 * dp) ++n.fluid_in_skirt;
    for (const Point& w : walls_near)
      if (distance(p, w) < 0.5 * dp) {
        ++n.fluid_touching_wall;
        break;
      }
    if (p.z > 0 && p.z < top) (p.r() < R ? inside : sinus).push_back(p);
  }
  for (const Point& a : inside)
    for (const Point& b : sinus) {
      const double d = distance(a, b);
      n.closest_across = std::min(n.closest_across, d / dp);
      if (d < n.support) ++n.pairs_across;
    }
  return n;
}

void expect_sealed(const std::string& name) {
  const fs::path file = fs::path(VALVEFSI_CASES_DIR) / name;
  SCOPED_TRACE(file.string());
  const SealCount n = count_seal(file);
  std::printf("%s: %d skirt wall particles, %d blood in the skirt, %d touching a wall, %d inside-sinus pairs within a support, closest %.3f dp; "
              "attachment line: %d of %d points nearer blood than wall, farthest wall %.3f dp\n",
              name.c_str(), n.skirt_walls, n.fluid_in_skirt, n.fluid_touching_wall, n.pairs_across, n.closest_across,
              n.attachment_open, n.attachment_samples, n.attachment_farthest_wall);
  // the band holds the wall: three columns per dp of circumference over the wedge (and its margin)
  EXPECT_GT(n.skirt_walls, 100);
  EXPECT_EQ(n.fluid_in_skirt, 0);
  EXPECT_EQ(n.fluid_touching_wall, 0);
  EXPECT_EQ(n.pairs_across, 0) << "closest inside-sinus pair " << n.closest_across << " dp, support " << n.support / n.dp << " dp";
  EXPECT_GT(n.closest_across * n.dp, n.support);
  // the attachment line lies inside the wall: every point's nearest particle is a wall particle,
  // no farther than the hex-prism lattice's covering radius ((dp^2/4 + a^2/3)^1/2 = 0.797 dp,
  // a = dp (2/sqrt 3)^1/2); the skirt from the stent radius left 331 of 501 points open, 1.34 dp
  EXPECT_EQ(n.attachment_open, 0) << "of " << n.attachment_samples;
  EXPECT_LE(n.attachment_farthest_wall, 0.8);
}

TEST(SceneSkirtSeal, CoarseSectorOnTheHexPrismLattice) { expect_sealed("fsi-mhgo-sector-coarse.textproto"); }

TEST(SceneSkirtSeal, MediumSectorOnTheHexPrismLattice) { expect_sealed("fsi-ogden-sector-medium.textproto"); }

}  // namespace
