#include "iqn_ils_acceleration.hpp"

#include "constant_relaxation.hpp"

#include <Eigen/QR>

#include <algorithm>

namespace valvefsi::coupling {

IqnIlsAcceleration::IqnIlsAcceleration(const AccelerationOptions& options) : options_(options) {}

void IqnIlsAcceleration::begin_window() {
  // Columns of an unfinished window (no end_window call) describe a state that was abandoned.
  std::erase_if(columns_, [](const Column& c) { return c.windows_ago == 0; });
  has_previous_ = false;
}

void IqnIlsAcceleration::end_window() {
  for (Column& c : columns_) ++c.windows_ago;
  std::erase_if(columns_, [&](const Column& c) { return c.windows_ago > options_.reused_windows; });
  has_previous_ = false;
}

void IqnIlsAcceleration::drop_columns_beyond_capacity(Eigen::Index interface_size) {
  // More columns than unknowns are necessarily dependent; the oldest go first.
  const auto capacity = static_cast<std::size_t>(std::min<Eigen::Index>(options_.max_columns, interface_size));
  while (columns_.size() > capacity) columns_.pop_back();
}

void IqnIlsAcceleration::filter_dependent_columns() {
  // QR filter: in V = QR (newest column first) |R_jj| is the part of column j not already
  // spanned by the newer columns; drop the column when that is below epsilon |v_j|, then redo.
  for (;;) {
    const Eigen::Index n = columns_.front().residual_change.size();
    Eigen::MatrixXd v(n, static_cast<Eigen::Index>(columns_.size()));
    for (std::size_t j = 0; j < columns_.size(); ++j) v.col(static_cast<Eigen::Index>(j)) = columns_[j].residual_change;
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(v);
    bool removed = false;
    for (Eigen::Index j = 0; j < v.cols(); ++j) {
      if (std::abs(qr.matrixQR()(j, j)) <= options_.filter_epsilon * v.col(j).norm()) {
        columns_.erase(columns_.begin() + j);
        removed = true;
        break;
      }
    }
    if (!removed || columns_.empty()) return;
  }
}

Eigen::VectorXd IqnIlsAcceleration::next_input(const Eigen::VectorXd& input, const Eigen::VectorXd& output) {
  check_same_size(input, output);
  if (!columns_.empty() && columns_.front().residual_change.size() != input.size()) columns_.clear();
  const Eigen::VectorXd residual = output - input;
  if (has_previous_ && previous_residual_.size() == residual.size()) {
    columns_.push_front(Column{residual - previous_residual_, output - previous_output_, 0});
  }
  previous_residual_ = residual;
  previous_output_ = output;
  has_previous_ = true;

  drop_columns_beyond_capacity(input.size());
  if (!columns_.empty()) filter_dependent_columns();
  if (columns_.empty()) return input + options_.relaxation * residual;

  const auto m = static_cast<Eigen::Index>(columns_.size());
  Eigen::MatrixXd v(input.size(), m);
  Eigen::MatrixXd w(input.size(), m);
  for (Eigen::Index j = 0; j < m; ++j) {
    v.col(j) = columns_[static_cast<std::size_t>(j)].residual_change;
    w.col(j) = columns_[static_cast<std::size_t>(j)].output_change;
  }
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(v);
  const Eigen::VectorXd q_transpose_residual = (qr.householderQ().adjoint() * residual).head(m);
  const Eigen::VectorXd c =
      -qr.matrixQR().topLeftCorner(m, m).triangularView<Eigen::Upper>().solve(q_transpose_residual);
  return output + w * c;
}

}  // namespace valvefsi::coupling
