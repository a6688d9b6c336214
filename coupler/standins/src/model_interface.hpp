#pragma once
// How the numerics' model problems (valvefsi_model_problems) meet the wire: a rigid interface
// moving along x. The pistons use a 1 m x 1 m square in the y-z plane (4 nodes, 2 triangles);
// their data are the piston's [displacement, velocity] and the total force along x. The
// nonlinear fixed point uses one triangle: unknown i is node i's x-displacement, the fluid's
// datum i is the x-force on marker i. The fluid's markers sit on the solid's nodes.

#include <Eigen/Core>

#include <string>

#include "valvefsi/coupling/model_problems/model_participant.hpp"
#include "valvefsi/coupling/participant.hpp"

namespace valvefsi::standins {

// "piston" (4 nodes) or "fixed-point" (3 nodes), scaled so the total area is `area`.
coupling::InterfaceSurfaceData model_surface(const std::string& model, double area);

// Restart files of the model stand-ins: the model's state plus the wrapper's own numbers
// (`wrapper`), in restart_file_path(window.restart_directory, participant name).
void write_model_restart(const coupling::Window& window, const coupling::Participant& participant,
                         const coupling::model::ModelParticipant& model, const Eigen::VectorXd& wrapper);
// In a restarted run (session().restart_directory set): loads the model and returns the
// wrapper's numbers; otherwise returns an empty vector and leaves the model alone.
Eigen::VectorXd read_model_restart(const coupling::Participant& participant, coupling::model::ModelParticipant& model);

}  // namespace valvefsi::standins
