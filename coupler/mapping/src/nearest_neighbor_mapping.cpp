#include "point_cloud_tree.hpp"
#include "sparse_mappings.hpp"

#include <vector>

namespace valvefsi::coupling::detail {

Eigen::SparseMatrix<double, Eigen::RowMajor> nearest_neighbor_matrix(const InterfaceMesh& surface,
                                                                      const Eigen::Matrix3Xd& points) {
  const PointCloudTree nodes(surface.positions);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(points.cols()));
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    entries.emplace_back(i, nodes.nearest(points.col(i)).first, 1.0);
  }
  Eigen::SparseMatrix<double, Eigen::RowMajor> h(points.cols(), surface.positions.cols());
  h.setFromTriplets(entries.begin(), entries.end());
  return h;
}

}  // namespace valvefsi::coupling::detail
