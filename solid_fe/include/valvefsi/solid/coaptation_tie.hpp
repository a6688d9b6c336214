#pragma once
// Coaptation tie of 2D strips (docs/solid_fe.md, "Coaptation tie"): a closed 2D flap has no
// stiffness against opening (docs/fsi-2d.md), so a tip that touches the coaptation (annulus)
// plane is held there both ways, normal and tangential, by a penalty spring to the point where it
// touched, until the tie would have to pull it back harder than a release force. It then lets go
// and catches the tip again the next time it touches. The spring has the contact penalty's
// stiffness, so the stable step is unchanged, and its work is booked in the energy ledger.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "valvefsi/solid/mesh.hpp"

namespace valvefsi::solid {

struct CoaptationTie {
  Plane plane;  // one of the solver's contact planes; normal towards the leaflet's side
  // Nodes caught and released together (2D: a tip's front/back pair, which move alike).
  std::vector<std::vector<std::int64_t>> groups;
  // A tied group lets go when the summed tie force on it pulls away from the plane's side
  // (towards -normal) and its magnitude exceeds this (N; 2D: release force per unit depth x depth).
  double release_force = 0.0;
};

// What the tie remembers (part of SolverState: restored with checkpoints and restart files).
struct CoaptationTieState {
  std::vector<std::uint8_t> tied;  // per group
  Eigen::Matrix3Xd anchor;         // per node of the groups, in group order (m)
  std::int64_t captures = 0;       // group catches so far
  std::int64_t releases = 0;       // group releases so far
  double peak_force = 0.0;         // largest pulling force on a tied group so far (N)
};

}  // namespace valvefsi::solid
