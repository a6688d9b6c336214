#pragma once
// The explicit integrator over 8-node bricks (docs/solid_fe-hexahedron.md): ExplicitSolver with
// the brick model, its 3D material and the pressure-loaded faces.
#include <functional>
#include <memory>
#include <vector>

#include "valvefsi/solid/explicit_solver.hpp"
#include "valvefsi/solid/hexahedron_elements.hpp"

namespace valvefsi::solid {

using HexahedronState = SolverState;
using HexahedronEnergy = EnergyBalance;
using HexahedronSolverOptions = SolverOptions;

class HexahedronSolver : public ExplicitSolver {
 public:
  HexahedronSolver(HexahedronModel model, SolidMaterial material, SolverOptions options = {})
      : ExplicitSolver(std::make_unique<HexahedronElements>(std::move(model), std::move(material)), options) {}

  // Follower pressure dp(t) (Pa) on `faces`.
  void set_pressure(std::function<double(double)> pressure_Pa, std::vector<PressureFace> faces) {
    bricks().set_pressure_faces(std::move(faces));
    set_pressure_waveform(std::move(pressure_Pa));
  }
  const HexahedronModel& model() const { return bricks_view().model(); }
  const SolidMaterial& material() const { return bricks_view().material(); }
  // Maximum principal stress and log strain on the two leaflet faces (bending included).
  void surface_fields(Eigen::VectorXd& max_principal_stress, Eigen::VectorXd& max_principal_log_strain) const {
    bricks_view().surface_fields(state().position, max_principal_stress, max_principal_log_strain);
  }

 private:
  HexahedronElements& bricks() { return static_cast<HexahedronElements&>(mutable_elements()); }
  const HexahedronElements& bricks_view() const { return static_cast<const HexahedronElements&>(elements()); }
};

}  // namespace valvefsi::solid
