// Experiment program for the 2D thin-wall scenes on FluidSolver<2> with the thin-wall model:
// runs one scene and writes its time series (force on the wall, plate motion, corrections,
// leaks) and optional per-marker and per-particle fits as CSV for docs/thin-leaflet.md.
#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <numbers>
#include <string>
#include <vector>
#include <array>

#include "valvefsi/fluid/thin_wall/scenes_2d.hpp"
#include "valvefsi/fluid/thin_wall/solver_run_2d.hpp"

using namespace valvefsi::fluid;
using namespace valvefsi::fluid::thin_wall;

int main(int argc, char** argv) {
  CLI::App app{"2D thin-wall scenes: two_levels, gap, plate"};
  std::string scene = "two_levels", output, marker_output, field_output;
  double dp = 0.025, end_time = 1.0, gap = 0.1, shifting = 0.0, sample_interval = 1e-3;
  double lattice_ratio = 0.5, background = 0.0, h_ratio = 1.3;
  std::string kernel = "cubic";
  double window = 1e-3;
  bool half_plane = false, opposite_beyond_edge = false, fluid_velocity_beyond_edge = false, round_edge = false, round_edge_velocity = false, normal_continuity = false;
  OscillatingPlate plate;
  app.add_option("--scene", scene, "two_levels | gap | plate")->check(CLI::IsMember({"two_levels", "gap", "plate"}));
  app.add_option("--dp", dp, "particle spacing (m)");
  app.add_option("--end", end_time, "end time (s)");
  app.add_option("--gap", gap, "gap under the wall (m), scene gap");
  app.add_option("--shifting", shifting, "particle shifting coefficient A (0: off)");
  app.add_option("--lattice-ratio", lattice_ratio, "virtual lattice spacing / dp");
  app.add_flag("--half-plane", half_plane, "count the whole half-plane lattice, not only the wall's shadow");
  app.add_flag("--opposite-beyond-edge", opposite_beyond_edge, "virtual points beyond a free end carry the other side's state");
  app.add_flag("--fluid-velocity-beyond-edge", fluid_velocity_beyond_edge, "virtual points beyond a free end move with the fluid");
  app.add_flag("--round-edge", round_edge, "virtual points reachable round a free end within R carry the other side's state");
  app.add_flag("--round-edge-velocity", round_edge_velocity, "virtual points reachable round a free end within R move with the fluid");
  double attached_end_y = std::numeric_limits<double>::quiet_NaN();
  app.add_option("--attached-end-y", attached_end_y, "two_levels: y of the wall's lower end (0: flush with the floor; default buried 3 dp)");
  app.add_option("--window", window, "motion window (s): the wall's targets are set at window ends, as the coupler does");
  app.add_flag("--normal-continuity", normal_continuity, "virtual points compress only by the wall's normal motion");
  app.add_option("--plate-width", plate.plate_width, "plate width b (m)");
  app.add_option("--amplitude", plate.amplitude, "plate amplitude A (m)");
  app.add_option("--period", plate.period, "plate period (s)");
  app.add_option("--box-length", plate.box_length, "box length along the motion (m)");
  app.add_option("--box-height", plate.box_height, "box height along the plate (m)");
  app.add_option("--viscosity", plate.viscosity, "dynamic viscosity (Pa s), plate scene");
  app.add_option("--h-ratio", h_ratio, "smoothing length / dp");
  app.add_option("--kernel", kernel, "cubic | wendland")->check(CLI::IsMember({"cubic", "wendland"}));
  app.add_option("--background", background, "background pressure (Pa)");
  app.add_option("--sample", sample_interval, "output interval (s)");
  app.add_option("--output", output, "CSV file of the time series");
  app.add_option("--marker-output", marker_output, "CSV file of every marker's force (x) over time");
  app.add_option("--field-output", field_output,
                 "plate scene: CSV of the fluid pressure's in-phase coefficient p = alpha w^2 X + beta w V + c, "
                 "fitted per particle after the first period, at its mean position");
  CLI11_PARSE(app, argc, argv);

  ThinWallCase2D c = scene == "plate" ? oscillating_plate_box(dp, plate)
                                       : two_level_tank(dp, 1.0, 0.5, scene == "gap" ? gap : 0.0);
  if (!std::isnan(attached_end_y)) c.walls.front().position.front()[1] = attached_end_y;
  c.fluid.shifting = shifting;
  c.fluid.background_pressure = background;
  c.fluid.smoothing_length_ratio = h_ratio;
  c.fluid.kernel = kernel == "cubic" ? KernelType::cubic_spline : KernelType::wendland_c2;
  c.wall_settings.virtual_spacing_ratio = lattice_ratio;
  c.wall_settings.shadow_only = !half_plane;
  c.wall_settings.opposite_state_beyond_edge = opposite_beyond_edge;
  c.wall_settings.fluid_velocity_beyond_edge = fluid_velocity_beyond_edge;
  c.wall_settings.other_side_round_edge = round_edge;
  c.wall_settings.fluid_velocity_round_edge = round_edge_velocity;
  c.wall_settings.normal_only_continuity = normal_continuity;
  const auto start = std::chrono::steady_clock::now();
  auto run = [&](auto& flow) -> int {
  std::ofstream csv;
  if (!output.empty()) {
    csv.open(output);
    csv << "time,force_x,force_y,wall_x,wall_vx,left_count,right_count,corrections,leaks,rejected_shifts,max_speed\n";
  }
  std::ofstream markers_csv;
  if (!marker_output.empty()) {
    markers_csv.open(marker_output);
    markers_csv << "time";
    for (const auto& m : flow.wall_model().markers().markers()) markers_csv << ",s" << m.arc_length;
    markers_csv << '\n';
  }
  // Per-particle (by id) least squares of the pressure against (w^2 X, w V, 1), plate scene,
  // with the particle's mean position: particles move little (KC = 0.3), so each one samples
  // the pressure field at about one place.
  const double omega = 2 * std::numbers::pi / plate.period;
  std::vector<std::array<double, 18>> field(field_output.empty() ? 0 : flow.particles().size());
  double next = 0;
  while (flow.time() < end_time * (1 - 1e-12)) {
    flow.step();
    if (!field.empty() && flow.time() >= plate.period) {
      const auto& p = flow.particles();
      const auto& w = flow.wall_model().wall();
      const std::array<double, 3> row{omega * omega * w.position[0][0], omega * w.velocity[0][0], 1.0};
      for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kind[i] != Kind::fluid) continue;
        auto& f = field[p.id[i]];
        const double pr = p.pressure[i] - flow.settings().background_pressure;
        f[10] += p.position[0][i];
        f[11] += p.position[1][i];
        int k = 0;
        for (int r = 0; r < 3; ++r)
          for (int c2 = r; c2 < 3; ++c2) f[k++] += row[r] * row[c2];
        for (int r = 0; r < 3; ++r) {
          f[6 + r] += row[r] * pr;
          f[12 + r] += row[r] * p.velocity[0][i];
          f[15 + r] += row[r] * p.velocity[1][i];
        }
        f[9] += 1;
      }
    }
    if (flow.time() + 1e-12 >= next) {
      next += sample_interval;
      const auto& p = flow.particles();
      const double xw = flow.wall_model().wall().position[0][0];
      std::size_t left = 0, right = 0;
      double vmax = 0;
      for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kind[i] != Kind::fluid) continue;
        (p.position[0][i] < (scene == "plate" ? xw : 0.5) ? left : right)++;
        vmax = std::max(vmax, std::hypot(double(p.velocity[0][i]), double(p.velocity[1][i])));
      }
      const auto& k = flow.wall_model().counters();
      if (csv) csv << flow.time() << ',' << flow.wall_force()[0] << ',' << flow.wall_force()[1] << ',' << xw << ',' << flow.wall_model().wall().velocity[0][0] << ',' << left << ','
                   << right << ',' << k.corrections << ',' << k.leaks << ',' << k.rejected_shifts << ',' << vmax << '\n';
      if (markers_csv) {
        markers_csv << flow.time();
        for (const auto& m : flow.wall_model().markers().markers()) markers_csv << ',' << m.force[0];
        markers_csv << '\n';
      }
      if (!std::isfinite(vmax) || vmax > 100) {
        spdlog::error("blow-up at t = {:.4f} s", flow.time());
        return 1;
      }
    }
  }
  if (!field.empty()) {
    std::ofstream out(field_output);
    out << "x,y,samples,alpha,beta,c,vx_per_V,vy_per_V\n";
    for (const auto& f : field) {
        if (f[9] < 10) continue;
        // Solve the 3x3 normal equations (symmetric, packed upper triangle) by Cramer's rule.
        const double a = f[0], b = f[1], c2 = f[2], d = f[3], e = f[4], g = f[5];
        const double det = a * (d * g - e * e) - b * (b * g - e * c2) + c2 * (b * e - d * c2);
        if (std::abs(det) < 1e-300) continue;
        // Cramer's rule for the right-hand side starting at f[k]; returns the three coefficients.
        auto solve = [&](int k) {
          const double r0 = f[k], r1 = f[k + 1], r2 = f[k + 2];
          return std::array<double, 3>{
              (r0 * (d * g - e * e) - b * (r1 * g - e * r2) + c2 * (r1 * e - d * r2)) / det,
              (a * (r1 * g - e * r2) - r0 * (b * g - e * c2) + c2 * (b * r2 - r1 * c2)) / det,
              (a * (d * r2 - r1 * e) - b * (b * r2 - r1 * c2) + r0 * (b * e - d * c2)) / det};
        };
        const auto [x0, x1, x2] = solve(6);
        // Velocity in phase with the plate's: v = beta (w V) + ..., so v / V = beta w.
        const double vx = solve(12)[1] * omega, vy = solve(15)[1] * omega;
        out << f[10] / f[9] << ',' << f[11] / f[9] << ',' << f[9] << ',' << x0 << ',' << x1 << ',' << x2 << ',' << vx << ',' << vy << '\n';
      }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  spdlog::info("{} dp={} t={} steps={} wall {:.1f} s ({:.2f} ms/step); corrections {} leaks {} lost {}", scene, dp, flow.time(),
               flow.step_count(), seconds, 1e3 * seconds / flow.step_count(), flow.wall_model().counters().corrections,
               flow.wall_model().counters().leaks, flow.lost_count());
  return 0;
  };
  ThinWallSolverRun2D flow(std::move(c), window);
  return run(flow);
}
