#pragma once
// The explicit integrator over shell triangles (docs/solid_fe.md): ExplicitSolver with the
// shell's model, material and the set of pressure-loaded triangles.
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "valvefsi/solid/explicit_solver.hpp"
#include "valvefsi/solid/shell_elements.hpp"

namespace valvefsi::solid {

using ShellState = SolverState;

class ShellSolver : public ExplicitSolver {
 public:
  ShellSolver(ShellModel model, Material material, SolverOptions options = {})
      : ExplicitSolver(std::make_unique<ShellElements>(std::move(model), std::move(material)), options) {}

  // Uniform transvalvular pressure dp(t) (Pa) on `elements` (all triangles when empty):
  // nodal force = dp * (current area vector) / 3, i.e. along +normal for dp > 0.
  void set_pressure(std::function<double(double)> pressure_Pa, std::vector<std::int64_t> elements = {}) {
    shell().set_pressure_elements(std::move(elements));
    set_pressure_waveform(std::move(pressure_Pa));
  }
  const ShellModel& model() const { return static_cast<const ShellElements&>(elements()).model(); }
  const Material& material() const { return static_cast<const ShellElements&>(elements()).material(); }

 private:
  ShellElements& shell() { return static_cast<ShellElements&>(mutable_elements()); }
};

}  // namespace valvefsi::solid
