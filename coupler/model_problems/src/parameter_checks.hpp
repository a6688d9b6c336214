#pragma once
// Range checks for model parameters; the message names the model, the field, the value and the range.

#include <Eigen/Core>

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace valvefsi::coupling::model {

inline void parameter_error(const std::string& model, const std::string& field, double value, const std::string& allowed) {
  std::ostringstream message;
  message << model << ": field '" << field << "' has value " << value << "; allowed: " << allowed;
  throw std::invalid_argument(message.str());
}
inline void require_positive(const std::string& model, const std::string& field, double value) {
  if (!(std::isfinite(value) && value > 0.0)) parameter_error(model, field, value, "a finite value > 0");
}
inline void require_at_least(const std::string& model, const std::string& field, double value, double low) {
  if (!(std::isfinite(value) && value >= low)) {
    std::ostringstream allowed;
    allowed << "a finite value >= " << low;
    parameter_error(model, field, value, allowed.str());
  }
}
inline void require_in(const std::string& model, const std::string& field, double value, double low, double high) {
  if (!(std::isfinite(value) && value >= low && value <= high)) {
    std::ostringstream allowed;
    allowed << "[" << low << ", " << high << "]";
    parameter_error(model, field, value, allowed.str());
  }
}
inline void require_size(const std::string& model, const std::string& field, const Eigen::VectorXd& data, Eigen::Index size) {
  if (data.size() != size) {
    std::ostringstream allowed;
    allowed << size << " entries";
    parameter_error(model, field + " size", static_cast<double>(data.size()), allowed.str());
  }
}

}  // namespace valvefsi::coupling::model
