#pragma once
// The coupler's watch for a slow interface runaway (docs/coupling.md, "When the coupling fails").
//
// The added-mass instability of explicit coupling lives on the scale of the coupling window (the
// 1D piston's growing mode has a period of 2-4 windows), while a leaflet's physical motion, its
// closing and its ringing included, is smooth over a window (~100 windows per period or more).
// So the watch follows each solid interface node's velocity jump between windows,
// d_n = v_n - 2 v_{n-1} + v_{n-2} (the velocity's departure from the line through the two
// windows before), as its root mean square over blocks of `kBlockWindows` windows, and takes the
// largest node: the block's "window-scale oscillation" (m/s). An event (the start, the tips'
// impact and chatter at closure) raises it for a few blocks and it falls again; a runaway raises
// it block after block. The watch fires when it has grown in each of the last `growing_blocks`
// blocks, by at least kGrowthFactor over them, and stands at or above `floor_speed`.
// A second rule catches an instability that jumps to its saturated level within a block or two
// and stays there (the 3D sector at a fluid CFL of 0.21: 0.3 -> 9.3 m/s in 2 ms, then level, so
// never 12 growing blocks): the watch also fires when the last `standing_blocks` blocks all stand
// at or above `standing_speed`. A jolt at closure passes in a few blocks; 0 switches the rule off.
#include <Eigen/Core>

#include <cstdint>
#include <deque>
#include <optional>

namespace valvefsi::coupler {

class OscillationWatch {
 public:
  static constexpr int kBlockWindows = 16;
  static constexpr double kGrowthFactor = 1.25;

  // floor_speed <= 0 only measures (never fires) by the growth rule; standing_speed <= 0 turns
  // the standing rule off.
  OscillationWatch(double floor_speed, int growing_blocks, double standing_speed = 0.0, int standing_blocks = 8);

  // After each completed window, with the solid interface's end-of-window node velocities.
  // Returns the last completed block's window-scale oscillation (m/s; 0 before the first).
  double update(const Eigen::Matrix3Xd& velocities);

  // Set by update() when the watch fires.
  struct Alarm {
    bool standing = false;             // fired by the standing rule (else by growth)
    Eigen::Index node = 0;             // the largest node of the last block
    double oscillation = 0.0;          // its window-scale oscillation (m/s)
    double oscillation_before = 0.0;   // the largest node's, `blocks` blocks earlier (m/s)
    int blocks = 0;                    // growing_blocks, or standing_blocks for the standing rule
    int block_windows = kBlockWindows;
  };
  [[nodiscard]] const std::optional<Alarm>& alarm() const { return alarm_; }

 private:
  double floor_speed_;
  int growing_blocks_;
  double standing_speed_;
  int standing_blocks_;
  Eigen::Matrix3Xd previous_, before_previous_;
  Eigen::VectorXd sum_of_squares_;  // per node, this block so far
  std::uint64_t updates_ = 0;
  int in_block_ = 0;
  double last_block_ = 0.0;
  std::deque<double> blocks_;       // the last max(growing_blocks + 1, standing_blocks) blocks' values
  std::optional<Alarm> alarm_;
};

}  // namespace valvefsi::coupler
