#include "iqn_ils_acceleration.hpp"

#include <fmt/format.h>

#include <Eigen/QR>

#include <algorithm>
#include <stdexcept>

#include "constant_relaxation.hpp"

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

// Per column: residual change, output change (vectors) and its age in windows (integers).
CarriedState IqnIlsAcceleration::carried_state() const {
  CarriedState state;
  for (const Column& c : columns_) {
    state.vectors.push_back(c.residual_change);
    state.vectors.push_back(c.output_change);
    state.integers.push_back(c.windows_ago);
  }
  return state;
}

void IqnIlsAcceleration::restore_carried_state(const CarriedState& state) {
  if (state.vectors.size() != 2 * state.integers.size()) {
    throw std::invalid_argument(fmt::format("IQN-ILS restart state: {} vectors for {} columns; expected two per column",
                                            state.vectors.size(), state.integers.size()));
  }
  columns_.clear();
  for (std::size_t k = 0; k < state.integers.size(); ++k)
    columns_.push_back({state.vectors[2 * k], state.vectors[2 * k + 1], static_cast<int>(state.integers[k])});
  has_previous_ = false;
}

void IqnIlsAcceleration::drop_columns_beyond_capacity(Eigen::Index interface_size) {
  // More columns than unknowns are necessarily dependent; the oldest go first.
  const auto capacity = static_cast<std::size_t>(std::min<Eigen::Index>(options_.max_columns, interface_size));
  while (columns_.size() > capacity) columns_.pop_back();
}

Eigen::MatrixXd IqnIlsAcceleration::stacked(bool residual_changes) const {
  Eigen::MatrixXd m(columns_.front().residual_change.size(), static_cast<Eigen::Index>(columns_.size()));
  for (std::size_t j = 0; j < columns_.size(); ++j) {
    m.col(static_cast<Eigen::Index>(j)) = residual_changes ? columns_[j].residual_change : columns_[j].output_change;
  }
  return m;
}

Eigen::HouseholderQR<Eigen::MatrixXd> IqnIlsAcceleration::filtered_decomposition() {
  // QR filter: in V = QR (newest column first) |R_jj| is the part of column j not already
  // spanned by the newer columns; drop the column when that is below epsilon |v_j|, then redo.
  for (;;) {
    const Eigen::MatrixXd v = stacked(true);
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(v);
    Eigen::Index dependent = -1;
    for (Eigen::Index j = 0; j < v.cols() && dependent < 0; ++j) {
      if (std::abs(qr.matrixQR()(j, j)) <= options_.filter_epsilon * v.col(j).norm()) dependent = j;
    }
    if (dependent < 0) return qr;
    columns_.erase(columns_.begin() + dependent);
    if (columns_.empty()) return qr;
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
  if (columns_.empty()) return input + options_.relaxation * residual;
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr = filtered_decomposition();
  if (columns_.empty()) return input + options_.relaxation * residual;

  const auto m = static_cast<Eigen::Index>(columns_.size());
  const Eigen::MatrixXd w = stacked(false);
  const Eigen::VectorXd q_transpose_residual = (qr.householderQ().adjoint() * residual).head(m);
  const Eigen::VectorXd c =
      -qr.matrixQR().topLeftCorner(m, m).triangularView<Eigen::Upper>().solve(q_transpose_residual);
  return output + w * c;
}

}  // namespace valvefsi::coupling
