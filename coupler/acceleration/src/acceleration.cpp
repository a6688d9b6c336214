#include "valvefsi/coupling/acceleration.hpp"

#include "aitken_acceleration.hpp"
#include "constant_relaxation.hpp"
#include "iqn_ils_acceleration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace valvefsi::coupling {

namespace {
void require(bool ok, const std::string& field, double value, const std::string& allowed) {
  if (!ok) {
    throw std::invalid_argument("acceleration options: field '" + field + "' has value " +
                                std::to_string(value) + "; allowed: " + allowed);
  }
}
}  // namespace

std::unique_ptr<Acceleration> make_acceleration(const AccelerationOptions& options) {
  require(std::isfinite(options.relaxation) && options.relaxation > 0.0 && options.relaxation <= 2.0,
          "relaxation", options.relaxation, "0 < relaxation <= 2");
  switch (options.kind) {
    case AccelerationKind::constant_relaxation:
      return std::make_unique<ConstantRelaxation>(options.relaxation);
    case AccelerationKind::aitken:
      return std::make_unique<AitkenAcceleration>(options.relaxation);
    case AccelerationKind::iqn_ils:
      require(options.reused_windows >= 0, "reused_windows", options.reused_windows, "an integer >= 0");
      require(options.max_columns >= 1, "max_columns", options.max_columns, "an integer >= 1");
      require(std::isfinite(options.filter_epsilon) && options.filter_epsilon >= 0.0 &&
                  options.filter_epsilon < 1.0,
              "filter_epsilon", options.filter_epsilon, "0 <= filter_epsilon < 1");
      return std::make_unique<IqnIlsAcceleration>(options);
  }
  throw std::invalid_argument("acceleration options: field 'kind' has an unknown value " +
                              std::to_string(static_cast<int>(options.kind)));
}

AccelerationKind parse_acceleration_kind(std::string_view name) {
  if (name == "constant") return AccelerationKind::constant_relaxation;
  if (name == "aitken") return AccelerationKind::aitken;
  if (name == "iqn-ils") return AccelerationKind::iqn_ils;
  throw std::invalid_argument("unknown acceleration '" + std::string(name) +
                              "'; allowed: \"constant\", \"aitken\", \"iqn-ils\"");
}

double relative_residual(const Eigen::VectorXd& input, const Eigen::VectorXd& output) {
  if (input.size() != output.size()) {
    throw std::invalid_argument("relative_residual: input has " + std::to_string(input.size()) +
                                " entries but output has " + std::to_string(output.size()));
  }
  // The floor keeps a zero interface (a solid at rest) from dividing by zero.
  constexpr double tiny = 1e3 * std::numeric_limits<double>::min();
  return (output - input).norm() / std::max(output.norm(), tiny);
}

void check_same_size(const Eigen::VectorXd& input, const Eigen::VectorXd& output) {
  if (input.size() != output.size() || input.size() == 0) {
    throw std::invalid_argument("acceleration: input has " + std::to_string(input.size()) +
                                " entries and output has " + std::to_string(output.size()) +
                                "; they must be equal and non-zero");
  }
}

}  // namespace valvefsi::coupling
