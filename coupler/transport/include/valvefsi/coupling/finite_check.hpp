#pragma once
// NaN or infinity in an exchanged array stops the run; the message names who sent or was about
// to send it, which field and which entry, so the culprit can be found in the solver's output.

#include <cstddef>
#include <optional>
#include <span>
#include <string_view>

namespace valvefsi::coupling {

// Index of the first non-finite entry, if any.
std::optional<std::size_t> first_non_finite(std::span<const double> values);

// Throws RunAborted "participant 'fluid' sent a non-finite value in loads.forces at index 7
// (point 2, component y): nan" when `values` holds a NaN or infinity. `components` = 3 for
// per-point vectors, 1 for scalars, for the point/component part of the message.
void require_finite(std::span<const double> values, std::string_view who, std::string_view field,
                    int components = 3);

}  // namespace valvefsi::coupling
