#include "valvefsi/coupling/acceleration.hpp"

#include <stdexcept>

// Placeholder until the implementation lands (the header is committed first for the transport helper).
namespace valvefsi::coupling {
std::unique_ptr<Acceleration> make_acceleration(const AccelerationOptions&) {
  throw std::logic_error("make_acceleration: not implemented yet");
}
AccelerationKind parse_acceleration_kind(std::string_view) { throw std::logic_error("not implemented yet"); }
double relative_residual(const Eigen::VectorXd& input, const Eigen::VectorXd& output) {
  return (output - input).norm() / std::max(output.norm(), 1e-300);
}
}  // namespace valvefsi::coupling
