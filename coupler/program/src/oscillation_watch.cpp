#include "valvefsi/coupler/oscillation_watch.hpp"

#include <algorithm>
#include <cmath>

namespace valvefsi::coupler {

OscillationWatch::OscillationWatch(double floor_speed, int growing_blocks, double standing_speed, int standing_blocks)
    : floor_speed_(floor_speed),
      growing_blocks_(growing_blocks < 1 ? 1 : growing_blocks),
      standing_speed_(standing_speed),
      standing_blocks_(standing_blocks < 1 ? 1 : standing_blocks) {}

double OscillationWatch::update(const Eigen::Matrix3Xd& velocities) {
  if (velocities.cols() == 0) return 0.0;
  ++updates_;
  if (updates_ >= 3) {
    if (sum_of_squares_.size() != velocities.cols()) sum_of_squares_ = Eigen::VectorXd::Zero(velocities.cols());
    sum_of_squares_ += (velocities - 2.0 * previous_ + before_previous_).colwise().squaredNorm().transpose();
    if (++in_block_ == kBlockWindows) {
      Eigen::Index node = 0;
      last_block_ = std::sqrt(sum_of_squares_.maxCoeff(&node) / kBlockWindows);
      sum_of_squares_.setZero();
      in_block_ = 0;
      blocks_.push_back(last_block_);
      const int kept = std::max(growing_blocks_ + 1, standing_blocks_);
      if (static_cast<int>(blocks_.size()) > kept) blocks_.pop_front();
      const int count = static_cast<int>(blocks_.size());
      // The growth rule looks at the last growing_blocks + 1 blocks.
      const std::size_t first_grown = count > growing_blocks_ + 1 ? static_cast<std::size_t>(count - growing_blocks_ - 1) : 0;
      bool growing = count >= growing_blocks_ + 1;
      for (std::size_t k = first_grown + 1; growing && k < blocks_.size(); ++k) growing = blocks_[k] > blocks_[k - 1];
      // A NaN never compares greater, so a non-finite velocity is left to the transport's check.
      if (floor_speed_ > 0.0 && !alarm_ && growing && last_block_ >= floor_speed_ &&
          last_block_ >= kGrowthFactor * blocks_[first_grown]) {
        alarm_ = Alarm{false, node, last_block_, blocks_[first_grown], growing_blocks_, kBlockWindows};
      }
      bool standing = standing_speed_ > 0.0 && count >= standing_blocks_;
      const std::size_t first_standing = static_cast<std::size_t>(count - standing_blocks_);
      for (std::size_t k = first_standing; standing && k < blocks_.size(); ++k) standing = blocks_[k] >= standing_speed_;
      if (!alarm_ && standing) {
        alarm_ = Alarm{true, node, last_block_, blocks_[first_standing], standing_blocks_, kBlockWindows};
      }
    }
  }
  before_previous_ = updates_ >= 2 ? previous_ : velocities;
  previous_ = velocities;
  return last_block_;
}

}  // namespace valvefsi::coupler
