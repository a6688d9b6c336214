// 2D proof (e), coaptation: two parallel flaps (b = 0.1 m) close onto each other in a closed
// box of water, from 0.06 m apart to 0.004 m (0.4 dp) along a smooth step over 0.5 s. The
// water between them must leave along the gap, through its open ends, never through a flap:
// no leak, and the particles in the gap follow the film's volume. The pressure bound (of the
// squeeze flow's order) is the validation executable's, open (docs/thin-leaflet.md).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "valvefsi/fluid/thin_wall/scenes_2d.hpp"
#include "valvefsi/fluid/thin_wall/solver_run_2d.hpp"

namespace valvefsi::fluid::thin_wall {
namespace {

struct FlapsRun {
  std::size_t in_gap_start = 0, in_gap_end = 0, corrections = 0, leaks = 0, rejected = 0, lost = 0;
  double worst_volume_error = 0;  // particles in the gap minus the film's volume / dp^2, largest |.|
  double max_pressure_resolved = 0;  // max |p| while the film is at least 1.2 dp thick
  double max_pressure = 0;           // max |p| over the whole run
  double squeeze = 0;                // rho u^2 / 2 of the squeeze flow down to d = dp
};

FlapsRun run_flaps(double dp) {
  const ClosingFlaps flaps;
  ThinWallSolverRun2D flow(closing_flaps_box(dp, flaps));
  const double half = flaps.flap_length / 2;
  FlapsRun r;
  auto in_gap = [&](const Particles<2>& p, double d) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.kind[i] == Kind::fluid && std::abs(p.position[0][i]) < d && std::abs(p.position[1][i]) < half) ++n;
    return n;
  };
  r.in_gap_start = in_gap(flow.particles(), flaps.start_half_gap);
  const double end = 1.2 * flaps.duration;
  double next_check = 0.0;
  while (flow.time() < end - 1e-9) {
    flow.step();
    const auto& p = flow.particles();
    const double d = flaps.half_gap(flow.time());
    double pm = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.kind[i] == Kind::fluid) pm = std::max(pm, std::abs(double(p.pressure[i])));
    r.max_pressure = std::max(r.max_pressure, pm);
    if (d >= 1.2 * dp) r.max_pressure_resolved = std::max(r.max_pressure_resolved, pm);
    if (flow.time() >= next_check) {
      next_check += 0.02;
      const double film = 2 * d * flaps.flap_length / (dp * dp);
      const double error = static_cast<double>(in_gap(p, d)) - film;
      r.worst_volume_error = std::max(r.worst_volume_error, std::abs(error));
      if (std::getenv("THIN_WALL_TRACE"))
        std::printf("t %.3f d/dp %.2f in gap %zu (film %.1f) max|p| %.0f corrections %zu\n", flow.time(), d / dp,
                    in_gap(p, d), film, pm, flow.model().counters().corrections);
    }
  }
  r.in_gap_end = in_gap(flow.particles(), flaps.half_gap(flow.time()));
  const auto k = flow.model().counters();
  r.corrections = k.corrections;
  r.leaks = k.leaks;
  r.rejected = k.rejected_shifts;
  r.lost = flow.lost_count();
  // The squeeze flow's scale: water leaves the gap at about V b / (2 d) at half-gap d, down
  // to d = dp (below it the film is thinner than a particle).
  for (double t = 0; t < flaps.duration; t += 1e-3) {
    const double d = flaps.half_gap(t);
    if (d < dp) break;
    const double u = flaps.closing_speed(t) * half / d;
    r.squeeze = std::max(r.squeeze, 0.5 * 1000.0 * u * u);
  }
  std::printf("closing flaps dp = %.3f: %zu particles in the gap at the start, %zu at the end (film %.1f); worst "
              "|count - film volume / dp^2| %.1f; max |p| %.0f Pa while the film >= 1.2 dp, %.0f Pa overall (squeeze "
              "scale rho u^2/2 = %.0f Pa); corrections %zu leaks %zu rejected shifts %zu lost %zu\n",
              dp, r.in_gap_start, r.in_gap_end, 2 * flaps.end_half_gap * flaps.flap_length / (dp * dp), r.worst_volume_error,
              r.max_pressure_resolved, r.max_pressure, r.squeeze, r.corrections, r.leaks, r.rejected, r.lost);
  return r;
}

#if !THIN_WALL_FLAPS_VALIDATION
TEST(ThinWallClosingFlaps, GapWaterLeavesAlongTheGapNeverThroughAFlap) {
  omp_set_num_threads(1);  // ~900 particles
  const FlapsRun r = run_flaps(0.01);
  EXPECT_GT(r.in_gap_start, 40u);
  EXPECT_EQ(r.leaks, 0u);
  EXPECT_EQ(r.lost, 0u);
  // The water in the gap follows the film's volume all the way down to 0.4 dp: it leaves
  // along the gap as the flaps close (measured worst 4 particles of 60).
  EXPECT_LT(r.worst_volume_error, 6.0);
  EXPECT_LE(r.in_gap_end, 6u);
}
#else
// The target: pressure of the squeeze flow's order (rho u^2 / 2 = 73 Pa here) while
// the flaps close. NOT met yet (docs/thin-leaflet.md): spikes of a few kPa at put-backs while
// the film is resolved, and tens of kPa on the last particles trapped in a film of 0.2-0.5 dp.
TEST(ThinWallClosingFlaps, PressureOfTheSqueezeFlowsOrder) {
  const FlapsRun r = run_flaps(0.01);
  EXPECT_EQ(r.leaks, 0u);
  EXPECT_LT(r.max_pressure_resolved, 10.0 * r.squeeze);
  EXPECT_LT(r.max_pressure, 10.0 * r.squeeze);
}
#endif

}  // namespace
}  // namespace valvefsi::fluid::thin_wall
