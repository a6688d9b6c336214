#pragma once
// What the coupler can tell about an interface that runs away (docs/coupling.md, "When the
// coupling fails"), so that its stop names a cause it can actually see.
//
// The coupler sees the solid's interface velocities and the loads' work on the solid, window by
// window. From them it can tell two kinds of growth apart:
// - at the window's scale: the node's velocity swings within a few windows (the explicit
//   coupling's added-mass mode: 2-4 windows on the 1D piston, ~9 on the 2D valve). A smaller
//   window, implicit coupling or a heavier leaflet is the remedy;
// - smooth over many windows: the velocity follows a motion the window resolves. That is not the
//   coupling's added-mass instability (a smaller window or IQN-ILS grows as fast: the 3D closed
//   valve of docs/fsi-3d.md). Where its energy comes from, the coupler books too: the fluid gave
//   F . v dt (v the velocity it was sent), the solid took F . dx; the difference is created by the
//   explicit coupling's lag (the loads act on a motion one window old). Fluid's work positive:
//   from the fluid's side (tension, the fluid's step, resolution at the leaflet, sound speed);
//   else, the lag's positive: from the staggering (a smaller window or implicit coupling removes
//   that energy; the 2D valve at fluid CFL 0.2 is one: period ~19 windows, the lag 0.068 J against
//   the fluid's -0.064 J); else from the solid.
// The time scale is measured as an equivalent period: for v_n = A sin(w n) the velocity's jump
// d_n = v_n - 2 v_{n-1} + v_{n-2} is exactly -4 sin^2(w / 2) v_{n-1}, so
// RMS(d) / RMS(v centred) = 4 sin^2(pi / P) gives the period P in windows. It is taken of the
// jumps themselves (d's own jumps against d), not of the velocity: the jump filters out the
// leaflet's slow motion, so a window-scale mode riding on a faster motion shows its own period,
// which the velocity's hides.
#include <Eigen/Core>

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "valvefsi/coupler/coupler_settings.hpp"

namespace valvefsi::coupler {

// The last windows of the solid's interface: velocities and the loads' work.
class InterfaceHistory {
 public:
  static constexpr int kWindows = 16;     // the jumps measured (one watch block)
  static constexpr int kWorkBlocks = 4;   // blocks of kWindows whose load work is reported

  // After each completed window: the end-of-window node velocities (m/s), the loads' work on
  // the solid over the window (J; sum over nodes of F . (x_end - x_start)) and the work the fluid
  // gave for it (J; F . v dt with the velocity the fluid was sent: power_solid x size).
  void update(const Eigen::Matrix3Xd& velocities, double load_work, double fluid_work);

  // One node's velocities over the last kWindows + 4 windows (fewer early in a run), oldest first.
  [[nodiscard]] std::vector<Eigen::Vector3d> node_velocities(Eigen::Index node) const;
  // The loads' work over the last complete blocks of kWindows windows, counted back from the
  // last window (J, oldest first; fewer than kWorkBlocks early in a run).
  [[nodiscard]] std::deque<double> block_work() const;
  // The loads' work minus the fluid's over the same windows (J): the energy the coupling's lag
  // created at the interface (0 under implicit coupling, which sends the window's mean velocity).
  [[nodiscard]] double created_work() const;

 private:
  std::deque<Eigen::Matrix3Xd> velocities_;  // the last kWindows + 4
  std::deque<double> work_, fluid_work_;     // the last kWorkBlocks * kWindows
};

// The 1D piston's added-mass mode spans 2-4 windows, the 2D valve's at mu = 4 9.1 windows (the
// leaflet's stiffness slows it); a fluid-side growth the window resolves spans more (the 2D valve
// at fluid CFL 0.2: 18.7 windows for the velocity; the 3D closed valve's interface power: ~16-20).
// Between them, with a factor 1.3-1.6 to either side: up to 12 windows is window-scale.
inline constexpr double kWindowScalePeriod = 12.0;

struct RunawayDiagnosis {
  enum class Kind { too_early, window_scale, smooth_fluid_work, smooth_coupling_lag, smooth_no_fluid_work };
  Kind kind = Kind::too_early;
  Eigen::Index node = 0;
  int jumps = 0;                    // windows the jumps are measured over (up to kWindows)
  double jump_rms = 0.0;            // m/s, RMS of d
  double speed_rms = 0.0;           // m/s, RMS of the centred velocity over the same windows
  double velocity_period = 0.0;     // windows, from jump_rms / speed_rms
  double period_windows = 0.0;      // windows, the jumps' own equivalent period: the classification
  std::deque<double> block_work;    // J, oldest first, blocks of InterfaceHistory::kWindows
  double net_work = 0.0;            // J, their sum
  double created_work = 0.0;        // J, the part the coupling's lag created (InterfaceHistory)
  int positive_blocks = 0;
};

// Period P (windows) with RMS(d) / RMS(v) = 4 sin^2(pi / P); 2 for a ratio of 4 or more.
double equivalent_period(double jump_rms, double speed_rms);

RunawayDiagnosis diagnose_runaway(const InterfaceHistory& history, Eigen::Index node);

// The cause and the remedies, for the stop's message (one or more sentences, no trailing stop).
std::string explain_runaway(const RunawayDiagnosis& diagnosis, SchemeKind scheme);

}  // namespace valvefsi::coupler
