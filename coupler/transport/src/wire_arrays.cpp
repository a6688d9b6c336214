#include "valvefsi/coupling/wire_arrays.hpp"

#include <fmt/format.h>

#include <span>

#include "valvefsi/coupling/finite_check.hpp"
#include "valvefsi/coupling/transport_errors.hpp"

namespace valvefsi::coupling {

namespace {

void check_count(int size, int components, Eigen::Index expected_points, std::string_view sender,
                 std::string_view field) {
  const bool ok = expected_points < 0 ? size % components == 0
                                      : static_cast<Eigen::Index>(size) == components * expected_points;
  if (!ok) {
    throw ProtocolError(fmt::format("{} sent {} with {} values: expected {} per point{}", sender, field, size,
                                    components,
                                    expected_points < 0 ? std::string()
                                                        : fmt::format(" for {} points = {}", expected_points,
                                                                      components * expected_points)));
  }
}

}  // namespace

Eigen::Matrix3Xd unpack_points(const google::protobuf::RepeatedField<double>& values, Eigen::Index expected_points,
                               std::string_view sender, std::string_view field) {
  check_count(values.size(), 3, expected_points, sender, field);
  require_finite(std::span<const double>(values.data(), static_cast<std::size_t>(values.size())), sender, field, 3);
  return Eigen::Map<const Eigen::Matrix3Xd>(values.data(), 3, values.size() / 3);
}

Eigen::VectorXd unpack_scalars(const google::protobuf::RepeatedField<double>& values, Eigen::Index expected_points,
                               std::string_view sender, std::string_view field) {
  check_count(values.size(), 1, expected_points, sender, field);
  require_finite(std::span<const double>(values.data(), static_cast<std::size_t>(values.size())), sender, field, 1);
  return Eigen::Map<const Eigen::VectorXd>(values.data(), values.size());
}

void pack_points(const Eigen::Matrix3Xd& points, google::protobuf::RepeatedField<double>* out,
                 std::string_view sender, std::string_view field) {
  require_finite(std::span<const double>(points.data(), static_cast<std::size_t>(points.size())), sender, field, 3);
  out->Resize(static_cast<int>(points.size()), 0.0);
  Eigen::Map<Eigen::Matrix3Xd>(out->mutable_data(), 3, points.cols()) = points;
}

void pack_scalars(const Eigen::VectorXd& values, google::protobuf::RepeatedField<double>* out,
                  std::string_view sender, std::string_view field) {
  require_finite(std::span<const double>(values.data(), static_cast<std::size_t>(values.size())), sender, field, 1);
  out->Resize(static_cast<int>(values.size()), 0.0);
  Eigen::Map<Eigen::VectorXd>(out->mutable_data(), values.size()) = values;
}

}  // namespace valvefsi::coupling
