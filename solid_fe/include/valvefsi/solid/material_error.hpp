#pragma once
// Raised when a material cannot be evaluated at a state (exponential overflow, inverted
// element); the message names the material and the invariants or stretches that caused it.
#include <stdexcept>
#include <string>

namespace valvefsi::solid {

class MaterialStateError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Largest argument for which std::exp stays finite with margin for the products around it.
inline constexpr double kMaxExpArgument = 700.0;

}  // namespace valvefsi::solid
