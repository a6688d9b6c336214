#include "model_interface.hpp"

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

}  // namespace valvefsi::standins
