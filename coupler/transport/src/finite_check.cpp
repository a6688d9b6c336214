#include "valvefsi/coupling/finite_check.hpp"

#include <fmt/format.h>

#include <cmath>

#include "valvefsi/coupling/transport_errors.hpp"

namespace valvefsi::coupling {

std::optional<std::size_t> first_non_finite(std::span<const double> values) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) return i;
  }
  return std::nullopt;
}

void require_finite(std::span<const double> values, std::string_view who, std::string_view field,
                    int components) {
  const auto bad = first_non_finite(values);
  if (!bad) return;
  const std::size_t index = *bad;
  std::string where;
  if (components == 3) {
    constexpr const char* kAxis[] = {"x", "y", "z"};
    where = fmt::format(" (point {}, component {})", index / 3, kAxis[index % 3]);
  } else if (components > 1) {
    where = fmt::format(" (item {}, component {})", index / static_cast<std::size_t>(components),
                        index % static_cast<std::size_t>(components));
  }
  throw RunAborted(fmt::format("{}: non-finite value in {} at index {}{}: {}", who, field, index,
                               where, values[index]));
}

}  // namespace valvefsi::coupling
