// standin_model_solid: the numerics' model solids behind the real protocol (thin wrapper):
//   --model piston       PistonSolid (rigid piston, Newmark) driven by the total x-force
//   --model fixed-point  NonlinearFixedPointSolid, x = S(y)
// Prints "final u = .. m, v = .. m/s" or "final x = [..]" at the end; stops the run with a
// message when |u| exceeds --divergence-bound (a diverging explicit scheme).

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <memory>
#include <vector>

#include "model_interface.hpp"
#include "standin_common.hpp"
#include "valvefsi/coupling/model_problems/nonlinear_fixed_point.hpp"
#include "valvefsi/coupling/model_problems/piston_solid.hpp"

int main(int argc, char** argv) {
  namespace model = valvefsi::coupling::model;
  CLI::App app{"stand-in solid wrapping a model problem (piston or nonlinear fixed point)"};
  valvefsi::standins::StandinSettings common;
  std::string kind = "piston";
  model::PistonSolidParameters piston;
  double area = 1.0, divergence_bound = 1e3;
  valvefsi::standins::add_common_options(app, common);
  app.add_option("--model", kind, "piston | fixed-point")->check(CLI::IsMember({"piston", "fixed-point"}));
  app.add_option("--mass", piston.mass, "piston mass (kg)");
  app.add_option("--stiffness", piston.stiffness, "piston spring (N/m)");
  app.add_option("--external-force", piston.external_force, "constant force along +x (N)");
  app.add_option("--initial-acceleration", piston.initial_acceleration, "a(0) consistent with the initial forces (m/s^2)");
  app.add_option("--area", area, "interface area (m^2)");
  app.add_option("--divergence-bound", divergence_bound, "stop when |u| exceeds this (m)");
  CLI11_PARSE(app, argc, argv);

  std::unique_ptr<valvefsi::coupling::Participant> participant;
  return valvefsi::standins::run_guarded("standin_model_solid", participant, [&] {
    auto options = valvefsi::standins::participant_options(common, valvefsi::coupling::ParticipantRole::solid, "standin_model_solid/" + kind);
    options.can_restart = true;  // the model's state fits in a restart file
    participant = std::make_unique<valvefsi::coupling::Participant>(options);
    const auto surface = valvefsi::standins::model_surface(kind, area);
    const Eigen::Index nodes = surface.positions.cols();
    std::unique_ptr<model::ModelParticipant> solid;
    if (kind == "piston") {
      solid = std::make_unique<model::PistonSolid>(piston);
    } else {
      solid = std::make_unique<model::NonlinearFixedPointSolid>(model::NonlinearFixedPoint::standard());
    }
    // Model data -> motion of the rigid (piston) or per-node (fixed point) interface along x.
    auto motion_of = [&](const Eigen::VectorXd& data) {
      valvefsi::coupling::InterfaceMotion motion{surface.positions, Eigen::Matrix3Xd::Zero(3, nodes)};
      if (kind == "piston") {
        motion.positions.row(0).array() += data(0);
        motion.velocities.row(0).setConstant(data(1));
      } else {
        motion.positions.row(0) += data.transpose();
      }
      return motion;
    };
    Eigen::VectorXd data = solid->current_data();
    participant->initialize_solid(surface, motion_of(data));
    valvefsi::standins::read_model_restart(*participant, *solid);  // a restarted run: the saved state
    data = solid->current_data();
    valvefsi::coupling::Window window;
    while (participant->next_window(window)) {
      if (window.write_restart) valvefsi::standins::write_model_restart(window, *participant, *solid, Eigen::VectorXd());
      if (window.restore_checkpoint) solid->restore_checkpoint();
      if (window.save_checkpoint) solid->save_checkpoint();
      const Eigen::VectorXd input = kind == "piston" ? Eigen::VectorXd::Constant(1, window.loads.forces.row(0).sum())
                                                     : Eigen::VectorXd(window.loads.forces.row(0).transpose());
      data = solid->advance(window.size, input);
      if (!std::isfinite(data(0)) || std::abs(data(0)) > divergence_bound) {
        throw valvefsi::coupling::RunAborted(fmt::format(
            "participant 'solid': the coupled solution diverged: |u| = {:.3e} m > {} m in window {} (t = {} s)",
            std::abs(data(0)), divergence_bound, window.index, window.end()));
      }
      participant->complete_window(motion_of(data), 0.0);
    }
    if (kind == "piston") {
      spdlog::info("standin_model_solid: final u = {:.12e} m, v = {:.12e} m/s", data(0), data(1));
    } else {
      spdlog::info("standin_model_solid: final x = [{:.12e}]", fmt::join(std::vector<double>(data.data(), data.data() + data.size()), ", "));
    }
    participant->finalize();
  });
}
