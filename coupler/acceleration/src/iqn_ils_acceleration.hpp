#pragma once
// IQN-ILS: interface quasi-Newton with an inverse Jacobian from least squares
// (Degroote, Bathe & Vierendeels 2009). With r_k = H(x_k) - x_k and x~_k = H(x_k), the columns
//   V = [r_k - r_{k-1}, ...],  W = [x~_k - x~_{k-1}, ...]   (newest first)
// give x_{k+1} = x~_k + W c with c = argmin |V c + r_k|, solved by a QR decomposition of V.
// Columns nearly dependent on newer ones are removed first (QR filter, see filter_epsilon).
// Without any column (first iteration of the first window) it under-relaxes with omega.

#include "valvefsi/coupling/acceleration.hpp"

#include <Eigen/QR>

#include <deque>

namespace valvefsi::coupling {

class IqnIlsAcceleration final : public Acceleration {
 public:
  explicit IqnIlsAcceleration(const AccelerationOptions& options);
  void begin_window() override;
  Eigen::VectorXd next_input(const Eigen::VectorXd& input, const Eigen::VectorXd& output) override;
  void end_window() override;
  CarriedState carried_state() const override;
  void restore_carried_state(const CarriedState& state) override;

  // For tests and logs: the columns the last update used (after filtering).
  int column_count() const { return static_cast<int>(columns_.size()); }

 private:
  struct Column {
    Eigen::VectorXd residual_change;  // a column of V
    Eigen::VectorXd output_change;    // the matching column of W
    int windows_ago = 0;              // 0 = built in the current window
  };
  void drop_columns_beyond_capacity(Eigen::Index interface_size);
  Eigen::MatrixXd stacked(bool residual_changes) const;         // V (true) or W (false), newest first
  Eigen::HouseholderQR<Eigen::MatrixXd> filtered_decomposition();  // drops dependent columns, returns QR of V

  AccelerationOptions options_;
  std::deque<Column> columns_;  // newest first
  bool has_previous_ = false;
  Eigen::VectorXd previous_residual_;
  Eigen::VectorXd previous_output_;
};

}  // namespace valvefsi::coupling
