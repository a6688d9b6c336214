// standin_solid_plate: a rigid flat plate (nx x ny nodes over length x width in the plane
// z = 0, triangulated) that moves along z, either
//   - as a mass on a spring, m z'' + k z = F_z (F_z = total interface force), integrated
//     exactly over each window under the window's constant load, or
//   - with a prescribed motion z = A sin(2 pi f t) that ignores the loads (--amplitude > 0).
// It speaks the coupling protocol like solid_fe would, saves/restores for implicit schemes,
// and is used by tests and the stand-in case. The exact solution for a constant force F from
// rest is z(t) = F/k (1 - cos(w t)), w = sqrt(k/m).

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "standin_common.hpp"
#include "valvefsi/case/case_loader.hpp"

namespace {

using valvefsi::coupling::InterfaceMotion;
using valvefsi::coupling::InterfaceSurfaceData;

struct PlateState {
  double z = 0.0;
  double v = 0.0;
};

InterfaceSurfaceData make_plate(int nx, int ny, double length, double width) {
  InterfaceSurfaceData surface;
  surface.nodes_per_cell = 3;
  surface.positions.resize(3, nx * ny);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      surface.positions.col(j * nx + i) << length * i / (nx - 1), width * j / (ny - 1), 0.0;
    }
  }
  surface.cells.resize(3, 2 * (nx - 1) * (ny - 1));
  surface.node_areas = Eigen::VectorXd::Zero(nx * ny);
  int cell = 0;
  const double triangle_area = 0.5 * (length / (nx - 1)) * (width / (ny - 1));
  for (int j = 0; j + 1 < ny; ++j) {
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      for (const auto& tri : {std::array{a, b, d}, std::array{a, d, c}}) {
        surface.cells.col(cell++) << tri[0], tri[1], tri[2];
        for (int n : tri) surface.node_areas(n) += triangle_area / 3.0;
      }
    }
  }
  surface.node_thickness = Eigen::VectorXd::Constant(nx * ny, 2.5e-4);
  return surface;
}

InterfaceMotion motion_of(const InterfaceSurfaceData& surface, const PlateState& state) {
  InterfaceMotion motion{surface.positions, Eigen::Matrix3Xd::Zero(3, surface.positions.cols())};
  motion.positions.row(2).array() += state.z;
  motion.velocities.row(2).setConstant(state.v);
  return motion;
}

// Exact solution of m z'' + k z = F over dt from (z, v), F constant.
PlateState advance_spring(const PlateState& s, double force, double mass, double stiffness, double dt) {
  const double omega = std::sqrt(stiffness / mass);
  const double z_eq = force / stiffness;
  const double c = std::cos(omega * dt), sn = std::sin(omega * dt);
  return {z_eq + (s.z - z_eq) * c + s.v / omega * sn, -(s.z - z_eq) * omega * sn + s.v * c};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"stand-in solid: a rigid plate on a spring (or with prescribed motion) along z"};
  valvefsi::standins::StandinSettings common;
  int nx = 9, ny = 5;
  double length = 0.02, width = 0.01, mass = 1e-3, stiffness = 10.0, amplitude = 0.0, frequency = 1.0;
  double proposed_window = 0.0;
  valvefsi::standins::add_common_options(app, common);
  app.add_option("--nx", nx, "nodes along x")->check(CLI::Range(2, 100000));
  app.add_option("--ny", ny, "nodes along y")->check(CLI::Range(2, 100000));
  app.add_option("--length", length, "plate length along x (m)")->check(CLI::PositiveNumber);
  app.add_option("--width", width, "plate width along y (m)")->check(CLI::PositiveNumber);
  app.add_option("--mass", mass, "plate mass (kg)")->check(CLI::PositiveNumber);
  app.add_option("--stiffness", stiffness, "spring stiffness (N/m)")->check(CLI::PositiveNumber);
  app.add_option("--amplitude", amplitude, "prescribed motion amplitude (m); > 0 ignores the loads");
  app.add_option("--frequency", frequency, "prescribed motion frequency (Hz)")->check(CLI::PositiveNumber);
  app.add_option("--propose-window", proposed_window, "max_stable_window to propose (s), 0 = none");
  bool fe_only = false;
  double fe_pressure = 100.0;
  app.add_flag("--fe-only", fe_only, "run alone (no coupler) under a uniform --fe-pressure to the case's end time");
  app.add_option("--fe-pressure", fe_pressure, "FE-only: uniform pressure along +z (Pa)");
  CLI11_PARSE(app, argc, argv);

  std::unique_ptr<valvefsi::coupling::Participant> participant;
  if (fe_only) {
    // The same plate without a partner: the FE-only path of a real solid, in miniature.
    return valvefsi::standins::run_guarded("standin_solid_plate", participant, [&] {
      const double end_time = valvefsi::load_case(common.case_file).run().end_time();
      const auto surface = make_plate(nx, ny, length, width);
      const double force_z = fe_pressure * surface.node_areas.sum();
      PlateState state;
      const int windows = static_cast<int>(std::ceil(end_time / 1e-3 - 1e-9));
      for (int n = 0; n < windows; ++n) {
        state = advance_spring(state, force_z, mass, stiffness, std::min(1e-3, end_time - n * 1e-3));
      }
      spdlog::info("standin_solid_plate (FE-only): final z = {:.9e} m, v = {:.9e} m/s", state.z, state.v);
    });
  }
  return valvefsi::standins::run_guarded("standin_solid_plate", participant, [&] {
    participant = std::make_unique<valvefsi::coupling::Participant>(valvefsi::standins::participant_options(
        common, valvefsi::coupling::ParticipantRole::solid, "standin_solid_plate"));
    const auto surface = make_plate(nx, ny, length, width);
    PlateState state, checkpoint;
    auto prescribed = [&](double t) {
      const double w = 2.0 * std::numbers::pi * frequency;
      return PlateState{amplitude * std::sin(w * t), amplitude * w * std::cos(w * t)};
    };
    if (amplitude > 0.0) state = prescribed(0.0);
    participant->initialize_solid(surface, motion_of(surface, state));
    valvefsi::coupling::Window window;
    while (participant->next_window(window)) {
      if (window.restore_checkpoint) state = checkpoint;
      if (window.save_checkpoint) checkpoint = state;
      const double force_z = window.loads.forces.row(2).sum();
      state = amplitude > 0.0 ? prescribed(window.end())
                              : advance_spring(state, force_z, mass, stiffness, window.size);
      valvefsi::standins::simulate_step(common, window.index);
      auto motion = motion_of(surface, state);
      if (common.nan_at_window >= 0 && window.index == static_cast<std::uint64_t>(common.nan_at_window)) {
        motion.positions(2, 1) = std::numeric_limits<double>::quiet_NaN();
      }
      participant->complete_window(motion, proposed_window);
    }
    spdlog::info("standin_solid_plate: final z = {:.9e} m, v = {:.9e} m/s", state.z, state.v);
    participant->finalize();
  });
}
