#pragma once
// How the numerics' model problems (valvefsi_model_problems) meet the wire: a rigid interface
// moving along x. The pistons use a 1 m x 1 m square in the y-z plane (4 nodes, 2 triangles);
// their data are the piston's [displacement, velocity] and the total force along x. The
// nonlinear fixed point uses one triangle: unknown i is node i's x-displacement, the fluid's
// datum i is the x-force on marker i. The fluid's markers sit on the solid's nodes.

#include <Eigen/Core>

#include <string>

#include "valvefsi/coupling/participant.hpp"

namespace valvefsi::standins {

// "piston" (4 nodes) or "fixed-point" (3 nodes), scaled so the total area is `area`.
coupling::InterfaceSurfaceData model_surface(const std::string& model, double area);

}  // namespace valvefsi::standins
