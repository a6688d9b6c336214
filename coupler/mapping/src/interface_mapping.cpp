#include "valvefsi/coupling/interface_mapping.hpp"

#include <stdexcept>

// Placeholder until the implementation lands (the header is committed first for the transport helper).
namespace valvefsi::coupling {
InterfaceMapping::InterfaceMapping(Eigen::SparseMatrix<double, Eigen::RowMajor> h) : h_(std::move(h)) {}
InterfaceMapping InterfaceMapping::build(const InterfaceMesh&, const Eigen::Matrix3Xd&, const MappingOptions&) {
  throw std::logic_error("InterfaceMapping::build: not implemented yet");
}
Eigen::Matrix3Xd InterfaceMapping::map_consistent(const Eigen::Matrix3Xd& v) const { return v * h_.transpose(); }
Eigen::Matrix3Xd InterfaceMapping::map_conservative(const Eigen::Matrix3Xd& f) const { return f * h_; }
const Eigen::SparseMatrix<double, Eigen::RowMajor>& InterfaceMapping::matrix() const { return h_; }
Eigen::Index InterfaceMapping::point_count() const { return h_.rows(); }
Eigen::Index InterfaceMapping::node_count() const { return h_.cols(); }
MappingMethod parse_mapping_method(std::string_view) { throw std::logic_error("not implemented yet"); }
}  // namespace valvefsi::coupling
