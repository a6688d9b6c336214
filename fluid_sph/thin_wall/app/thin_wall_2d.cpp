// Experiment driver for the 2D thin-wall scenes: runs one scene and writes its time series
// (force on the wall, plate motion, corrections, leaks) as CSV for docs/thin-leaflet.md.
#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <string>

#include "valvefsi/fluid/thin_wall/scenes_2d.hpp"

using namespace valvefsi::fluid;
using namespace valvefsi::fluid::thin_wall;

int main(int argc, char** argv) {
  CLI::App app{"2D thin-wall scenes: two_levels, gap, plate"};
  std::string scene = "two_levels", output, marker_output;
  double dp = 0.025, end_time = 1.0, gap = 0.1, shifting = 0.0, sample_interval = 1e-3;
  double lattice_ratio = 0.5, background = 0.0, h_ratio = 1.3;
  std::string kernel = "cubic";
  bool half_plane = false, opposite_beyond_edge = false, fluid_velocity_beyond_edge = false;
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
  CLI11_PARSE(app, argc, argv);

  ThinWallCase2D c = scene == "plate" ? oscillating_plate_box(dp, plate)
                                       : two_level_tank(dp, 1.0, 0.5, scene == "gap" ? gap : 0.0);
  c.fluid.shifting = shifting;
  c.fluid.background_pressure = background;
  c.fluid.smoothing_length_ratio = h_ratio;
  c.fluid.kernel = kernel == "cubic" ? KernelType::cubic_spline : KernelType::wendland_c2;
  c.wall_settings.virtual_spacing_ratio = lattice_ratio;
  c.wall_settings.shadow_only = !half_plane;
  c.wall_settings.opposite_state_beyond_edge = opposite_beyond_edge;
  c.wall_settings.fluid_velocity_beyond_edge = fluid_velocity_beyond_edge;
  const auto start = std::chrono::steady_clock::now();
  ThinWallFlow2D flow(std::move(c));
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
  double next = 0;
  while (flow.time() < end_time * (1 - 1e-12)) {
    flow.step();
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
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  spdlog::info("{} dp={} t={} steps={} wall {:.1f} s ({:.2f} ms/step); corrections {} leaks {} lost {}", scene, dp, flow.time(),
               flow.step_count(), seconds, 1e3 * seconds / flow.step_count(), flow.wall_model().counters().corrections,
               flow.wall_model().counters().leaks, flow.lost_count());
  return 0;
}
