#include "model_interface.hpp"

#include "valvefsi/coupling/restart_file.hpp"

#include <cmath>
#include <stdexcept>

namespace valvefsi::standins {

coupling::InterfaceSurfaceData model_surface(const std::string& model, double area) {
  coupling::InterfaceSurfaceData surface;
  surface.nodes_per_cell = 3;
  if (model == "fixed-point") {
    const double side = std::sqrt(2.0 * area);  // right triangle with legs `side`
    surface.positions.resize(3, 3);
    surface.positions << 0.0, 0.0, 0.0, 0.0, side, 0.0, 0.0, 0.0, side;
    surface.cells.resize(3, 1);
    surface.cells << 0, 1, 2;
    surface.node_areas = Eigen::VectorXd::Constant(3, area / 3.0);
    return surface;
  }
  if (model != "piston") throw std::invalid_argument("model surface '" + model + "': allowed piston or fixed-point");
  const double side = std::sqrt(area);
  surface.positions.resize(3, 4);
  surface.positions << 0.0, 0.0, 0.0, 0.0,  //
      0.0, side, side, 0.0,                 //
      0.0, 0.0, side, side;
  surface.cells.resize(3, 2);
  surface.cells << 0, 0, 1, 2, 2, 3;
  surface.node_areas = Eigen::VectorXd::Constant(4, area / 4.0);
  return surface;
}

void write_model_restart(const coupling::Window& window, const coupling::Participant& participant,
                         const coupling::model::ModelParticipant& model, const Eigen::VectorXd& wrapper) {
  coupling::RestartWriter file(coupling::restart_file_path(window.restart_directory, participant.name()));
  const Eigen::VectorXd state = model.state_values();
  file.put("model_state", std::span<const double>(state.data(), static_cast<std::size_t>(state.size())));
  file.put("wrapper_state", std::span<const double>(wrapper.data(), static_cast<std::size_t>(wrapper.size())));
  file.commit();
}

Eigen::VectorXd read_model_restart(const coupling::Participant& participant, coupling::model::ModelParticipant& model) {
  const auto& folder = participant.session().restart_directory;
  if (folder.empty()) return {};
  const coupling::RestartReader file(coupling::restart_file_path(folder, participant.name()));
  const auto state = file.doubles("model_state");
  model.load_state_values(Eigen::Map<const Eigen::VectorXd>(state.data(), static_cast<Eigen::Index>(state.size())));
  const auto wrapper = file.doubles("wrapper_state");
  return Eigen::Map<const Eigen::VectorXd>(wrapper.data(), static_cast<Eigen::Index>(wrapper.size()));
}

}  // namespace valvefsi::standins
