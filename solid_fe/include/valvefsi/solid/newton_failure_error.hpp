#pragma once
// Raised when implicit dynamics cannot complete a step: Newton did not converge even after the
// step was cut below solid.implicit_min_step_s. A MaterialStateError, so the program stops as for
// a material failure (FE-only exit 3, coupled exit 6); the message names the time, the step, the
// residual and the node where it is largest, and what to change.
#include "valvefsi/solid/material_error.hpp"

namespace valvefsi::solid {

class NewtonFailureError : public MaterialStateError {
 public:
  using MaterialStateError::MaterialStateError;
};

}  // namespace valvefsi::solid
