// standin_model_fluid: the numerics' model fluids behind the real protocol (thin wrapper):
//   --model incompressible  IncompressiblePistonFluid (added mass rho L A)
//   --model acoustic        AcousticColumnFluid (1-D acoustic column, one step per window)
//   --model fixed-point     NonlinearFixedPointFluid, y = F(x)
// The models want the partner's state at the END of the window, [u, v]. The wire gives the
// markers' window-start position and the constant velocity through the window, so:
//   explicit schemes: u, v are the solid's start state (the models' explicit input, motion_n);
//   implicit scheme:  u_end = u + v dt, and v_end from the trapezoidal rule of the piston,
//                     v_end = 2 (u_end - u_start)/dt - v_start, exact for Newmark (1/4, 1/2).
// Its loads are the model's force along x, shared equally by the markers (fixed point: one
// datum per marker).

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <memory>

#include "model_interface.hpp"
#include "standin_common.hpp"
#include "valvefsi/coupling/model_problems/acoustic_column_fluid.hpp"
#include "valvefsi/coupling/model_problems/incompressible_piston_fluid.hpp"
#include "valvefsi/coupling/model_problems/nonlinear_fixed_point.hpp"

int main(int argc, char** argv) {
  namespace model = valvefsi::coupling::model;
  CLI::App app{"stand-in fluid wrapping a model problem (incompressible or acoustic piston, fixed point)"};
  valvefsi::standins::StandinSettings common;
  std::string kind = "incompressible";
  model::IncompressiblePistonFluidParameters incompressible;
  model::AcousticColumnParameters acoustic;
  std::string far_end = "non-reflecting";
  valvefsi::standins::add_common_options(app, common);
  app.add_option("--model", kind, "incompressible | acoustic | fixed-point")
      ->check(CLI::IsMember({"incompressible", "acoustic", "fixed-point"}));
  app.add_option("--density", incompressible.density, "fluid density (kg/m^3)");
  app.add_option("--column-length", incompressible.column_length, "fluid column length (m)");
  app.add_option("--area", incompressible.area, "piston area (m^2)");
  app.add_option("--initial-acceleration", incompressible.initial_acceleration, "incompressible: a(0) (m/s^2)");
  app.add_option("--sound-speed", acoustic.sound_speed, "acoustic: sound speed (m/s)");
  app.add_option("--cells", acoustic.cells, "acoustic: cells in the column");
  app.add_option("--far-end", far_end, "acoustic: non-reflecting | closed | open");
  CLI11_PARSE(app, argc, argv);
  acoustic.density = incompressible.density;
  acoustic.column_length = incompressible.column_length;
  acoustic.area = incompressible.area;

  std::unique_ptr<valvefsi::coupling::Participant> participant;
  return valvefsi::standins::run_guarded("standin_model_fluid", participant, [&] {
    auto options = valvefsi::standins::participant_options(common, valvefsi::coupling::ParticipantRole::fluid, "standin_model_fluid/" + kind);
    options.can_restart = true;  // the model's state fits in a restart file
    participant = std::make_unique<valvefsi::coupling::Participant>(options);
    std::unique_ptr<model::ModelParticipant> fluid;
    if (kind == "incompressible") {
      fluid = std::make_unique<model::IncompressiblePistonFluid>(incompressible);
    } else if (kind == "acoustic") {
      acoustic.far_end = model::parse_far_end(far_end);
      fluid = std::make_unique<model::AcousticColumnFluid>(acoustic);
    } else {
      fluid = std::make_unique<model::NonlinearFixedPointFluid>(model::NonlinearFixedPoint::standard());
    }
    Eigen::Matrix3Xd reference;
    participant->initialize_fluid([&](const valvefsi::coupling::InterfaceSurfaceData& surface) {
      reference = surface.positions;
      return valvefsi::coupling::InterfacePoints{surface.positions, surface.node_areas};
    });
    const bool implicit = participant->session().implicit;
    const Eigen::Index points = reference.cols();
    double start_velocity = 0.0, end_velocity = 0.0;
    std::uint64_t current_window = 0;
    if (const auto wrapper = valvefsi::standins::read_model_restart(*participant, *fluid); wrapper.size() > 0) {
      start_velocity = wrapper(0);
      end_velocity = wrapper(1);
      current_window = static_cast<std::uint64_t>(wrapper(2));
    }
    valvefsi::coupling::Window window;
    while (participant->next_window(window)) {
      if (window.write_restart) {
        valvefsi::standins::write_model_restart(
            window, *participant, *fluid,
            Eigen::Vector3d(start_velocity, end_velocity, static_cast<double>(current_window)));
      }
      if (window.restore_checkpoint) fluid->restore_checkpoint();
      if (window.save_checkpoint) fluid->save_checkpoint();
      if (window.index != current_window) {  // the previous window is done: its end is our start
        start_velocity = end_velocity;
        current_window = window.index;
      }
      const Eigen::VectorXd start = (window.motion.positions - reference).row(0).transpose();
      const Eigen::VectorXd velocity = window.motion.velocities.row(0).transpose();
      Eigen::VectorXd input;
      if (kind == "fixed-point") {
        input = implicit ? Eigen::VectorXd(start + window.size * velocity) : start;
      } else {
        const double u = start.mean() + (implicit ? window.size * velocity.mean() : 0.0);
        const double v = implicit ? 2.0 * velocity.mean() - start_velocity : velocity.mean();
        input = Eigen::Vector2d(u, v);
        end_velocity = v;
      }
      const Eigen::VectorXd output = fluid->advance(window.size, input);
      valvefsi::coupling::InterfaceLoads loads{Eigen::Matrix3Xd::Zero(3, points)};
      if (kind == "fixed-point") {
        loads.forces.row(0) = output.transpose();
      } else {
        loads.forces.row(0).setConstant(output(0) / static_cast<double>(points));
      }
      participant->complete_window(loads, 0.0);
    }
    participant->finalize();
  });
}
