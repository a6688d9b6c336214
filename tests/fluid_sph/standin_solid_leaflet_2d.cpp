// standin_solid_leaflet_2d: a 2D solid for the fluid's participant tests: one straight rigid
// leaflet (a polyline of --nodes nodes from (x, y0) to (x, y1), segments, z = 0), held still or
// moved along x with a prescribed x = A sin(2 pi f t). It ignores the loads except to report
// their window-averaged total ("mean received force = fx fy N/m" over t >= --average-from).
#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <cmath>
#include <numbers>

#include "standin_common.hpp"
#include "valvefsi/coupling/restart_file.hpp"

int main(int argc, char** argv) {
  CLI::App app{"2D stand-in solid: one straight rigid leaflet, still or oscillating along x"};
  valvefsi::standins::StandinSettings common;
  int nodes = 11;
  double x = 0.0, y0 = 0.0, y1 = 0.1, thickness = 2.5e-4, amplitude = 0.0, frequency = 1.0, average_from = 0.0;
  valvefsi::standins::add_common_options(app, common);
  app.add_option("--nodes", nodes, "nodes along the leaflet")->check(CLI::Range(2, 100000));
  app.add_option("--x", x, "x of the leaflet (m)");
  app.add_option("--y0", y0, "y of the first (attached) node (m)");
  app.add_option("--y1", y1, "y of the last (free) node (m)");
  app.add_option("--thickness", thickness, "leaflet thickness (m)")->check(CLI::PositiveNumber);
  app.add_option("--amplitude", amplitude, "prescribed x amplitude (m); 0: still");
  app.add_option("--frequency", frequency, "prescribed motion frequency (Hz)")->check(CLI::PositiveNumber);
  app.add_option("--average-from", average_from, "report the mean received force over windows ending after this time (s)");
  CLI11_PARSE(app, argc, argv);

  std::unique_ptr<valvefsi::coupling::Participant> participant;
  return valvefsi::standins::run_guarded("standin_solid_leaflet_2d", participant, [&] {
    auto options = valvefsi::standins::participant_options(common, valvefsi::coupling::ParticipantRole::solid,
                                                           "standin_solid_leaflet_2d");
    options.spatial_dimension = 2;
    options.can_restart = true;  // its state: the running sums of the mean force
    participant = std::make_unique<valvefsi::coupling::Participant>(options);
    valvefsi::coupling::InterfaceSurfaceData surface;
    surface.nodes_per_cell = 2;
    surface.positions = Eigen::Matrix3Xd::Zero(3, nodes);
    surface.cells.resize(2, nodes - 1);
    surface.node_areas = Eigen::VectorXd::Zero(nodes);
    const double segment = std::abs(y1 - y0) / (nodes - 1);
    for (int j = 0; j < nodes; ++j) {
      surface.positions.col(j) << x, y0 + (y1 - y0) * j / (nodes - 1), 0.0;
      if (j + 1 < nodes) {
        surface.cells.col(j) << j, j + 1;
        surface.node_areas(j) += 0.5 * segment;
        surface.node_areas(j + 1) += 0.5 * segment;
      }
    }
    surface.node_thickness = Eigen::VectorXd::Constant(nodes, thickness);
    const double omega = 2.0 * std::numbers::pi * frequency;
    auto motion_at = [&](double t) {
      valvefsi::coupling::InterfaceMotion m{surface.positions, Eigen::Matrix3Xd::Zero(3, nodes)};
      m.positions.row(0).array() += amplitude * std::sin(omega * t);
      m.velocities.row(0).setConstant(amplitude * omega * std::cos(omega * t));
      return m;
    };
    participant->initialize_solid(surface, motion_at(0.0));
    valvefsi::coupling::Window window;
    double sum_x = 0, sum_y = 0, sum_t = 0;
    if (const auto& folder = participant->session().restart_directory; !folder.empty()) {
      const valvefsi::coupling::RestartReader file(valvefsi::coupling::restart_file_path(folder, participant->name()));
      sum_x = file.scalar("sum_x");
      sum_y = file.scalar("sum_y");
      sum_t = file.scalar("sum_t");
    }
    while (participant->next_window(window)) {
      if (window.write_restart) {
        valvefsi::coupling::RestartWriter file(valvefsi::coupling::restart_file_path(window.restart_directory, participant->name()));
        file.put("sum_x", sum_x);
        file.put("sum_y", sum_y);
        file.put("sum_t", sum_t);
        file.commit();
      }
      valvefsi::standins::simulate_step(common, window.index);
      if (window.end() > average_from) {
        sum_x += window.size * window.loads.forces.row(0).sum();
        sum_y += window.size * window.loads.forces.row(1).sum();
        sum_t += window.size;
      }
      participant->complete_window(motion_at(window.end()), 0.0);
    }
    spdlog::info("standin_solid_leaflet_2d: mean received force = {:.9e} {:.9e} N/m over {} s", sum_x / std::max(sum_t, 1e-300),
                 sum_y / std::max(sum_t, 1e-300), sum_t);
    participant->finalize();
  });
}
