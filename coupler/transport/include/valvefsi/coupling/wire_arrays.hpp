#pragma once
// Packed repeated doubles on the wire <-> Eigen matrices in memory, with the checks every
// receiver needs: the length fits the point count and every value is finite (NaN stops the
// run with a message naming the sender, the field and the index).

#include <Eigen/Core>
#include <google/protobuf/repeated_field.h>

#include <cstdint>
#include <string_view>

namespace valvefsi::coupling {

// 3 x (size / 3) matrix of the x, y, z triples in `values`. Throws ProtocolError if the size
// is not 3 * expected_points (expected_points < 0: any multiple of 3), RunAborted on NaN/inf.
Eigen::Matrix3Xd unpack_points(const google::protobuf::RepeatedField<double>& values, Eigen::Index expected_points,
                               std::string_view sender, std::string_view field);

// One value per point; same checks with 1 component.
Eigen::VectorXd unpack_scalars(const google::protobuf::RepeatedField<double>& values, Eigen::Index expected_points,
                               std::string_view sender, std::string_view field);

// Replaces `out` with the columns of `points`; throws RunAborted on NaN/inf, naming `sender`
// (the side about to send) and `field`.
void pack_points(const Eigen::Matrix3Xd& points, google::protobuf::RepeatedField<double>* out,
                 std::string_view sender, std::string_view field);
void pack_scalars(const Eigen::VectorXd& values, google::protobuf::RepeatedField<double>* out,
                  std::string_view sender, std::string_view field);

}  // namespace valvefsi::coupling
