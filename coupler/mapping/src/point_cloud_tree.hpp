#pragma once
// A nanoflann k-d tree over the columns of a 3 x n matrix (the layout of all interface data).

#include <Eigen/Core>
#include <nanoflann.hpp>

#include <cstdint>
#include <utility>
#include <vector>

namespace valvefsi::coupling::detail {

// It keeps a reference to `points`, which must outlive the tree.
class PointCloudTree {
 public:
  explicit PointCloudTree(Eigen::Matrix3Xd&&) = delete;  // a temporary would dangle
  explicit PointCloudTree(const Eigen::Matrix3Xd& points)
      : adaptor_{points}, index_(3, adaptor_, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {}
  PointCloudTree(const PointCloudTree&) = delete;
  PointCloudTree& operator=(const PointCloudTree&) = delete;

  // Index of the nearest column and its squared distance.
  std::pair<Eigen::Index, double> nearest(const Eigen::Vector3d& query) const {
    std::uint32_t index = 0;
    double distance_squared = 0.0;
    index_.knnSearch(query.data(), 1, &index, &distance_squared);
    return {static_cast<Eigen::Index>(index), distance_squared};
  }

  // The k nearest columns (k <= count), nearest first.
  void nearest_k(const Eigen::Vector3d& query, int k, std::vector<std::uint32_t>& index,
                 std::vector<double>& distance_squared) const {
    index.resize(static_cast<std::size_t>(k));
    distance_squared.resize(static_cast<std::size_t>(k));
    const auto found = index_.knnSearch(query.data(), static_cast<std::size_t>(k), index.data(), distance_squared.data());
    index.resize(found);
    distance_squared.resize(found);
  }

  // All columns within `radius` (inclusive), as (index, squared distance), unsorted.
  void within(const Eigen::Vector3d& query, double radius,
              std::vector<std::pair<std::uint32_t, double>>& found) const {
    found.clear();
    index_.radiusSearch(query.data(), radius * radius, found, nanoflann::SearchParams(32, 0.0f, false));
  }

 private:
  struct Adaptor {
    const Eigen::Matrix3Xd& points;
    std::size_t kdtree_get_point_count() const { return static_cast<std::size_t>(points.cols()); }
    double kdtree_get_pt(std::size_t i, std::size_t dim) const {
      return points(static_cast<Eigen::Index>(dim), static_cast<Eigen::Index>(i));
    }
    template <class BoundingBox>
    bool kdtree_get_bbox(BoundingBox&) const { return false; }
  };
  using Index = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Adaptor>, Adaptor, 3,
                                                    std::uint32_t>;
  Adaptor adaptor_;
  Index index_;
};

}  // namespace valvefsi::coupling::detail
