// The calibrated stable step (Lanczos on M^-1 K, docs/solid_fe.md "Stable step"): on a small
// plate the central-difference run at the calibrated critical step 2/omega_max is stable just
// below it and blows up just above it, so the step used (safety x that) is within 20 % of the
// measured instability limit; and the Lanczos omega_max matches a long power iteration.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "test_meshes.hpp"
#include "valvefsi/solid/saint_venant_kirchhoff.hpp"
#include "valvefsi/solid/shell_solver.hpp"

namespace valvefsi::solid::testing {
namespace {

ShellModel small_plate() {
  const Mesh mesh = rectangular_plate(0.006, 0.004, 6, 4, 0.25e-3, false, 0.2);
  ShellModelOptions options;
  options.fixed_nodes = mesh.node_sets.at("left");
  return build_shell_model(mesh, options);
}

Eigen::Matrix3Xd small_random_velocity(Eigen::Index nodes) {
  Eigen::Matrix3Xd v(3, nodes);
  unsigned seed = 11;
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    seed = seed * 1103515245u + 12345u;
    v.data()[i] = 1e-6 * (static_cast<double>((seed >> 8) % 2001) / 1000.0 - 1.0);
  }
  return v;
}

// Whether a run of `steps` steps of fixed size dt from a small random velocity blows up (its
// largest speed grows 1000-fold or stops being finite).
bool blows_up(double dt, int steps) {
  SolverOptions options;
  options.fixed_time_step = dt;
  ShellSolver solver(small_plate(), SaintVenantKirchhoff(1e6, 0.3), options);
  solver.set_velocity(small_random_velocity(solver.model().reference_positions.cols()));
  solver.advance_window(steps * dt * (1 - 1e-12));
  const double speed = solver.state().velocity.cwiseAbs().maxCoeff();
  return !(speed < 1e-3) || !solver.state().velocity.allFinite();
}

TEST(StableStep, CalibratedStepIsWithinTwentyPercentOfTheMeasuredLimit) {
  SolverOptions options;
  options.time_step_calibration_interval = 1000000;  // once, at the first step
  options.max_step_calibration = 10.0;               // no cap: test the calibration itself
  ShellSolver solver(small_plate(), SaintVenantKirchhoff(1e6, 0.3), options);
  solver.set_velocity(small_random_velocity(solver.model().reference_positions.cols()));
  solver.advance_window(0.0);
  const double calibrated = solver.state().calibrated_step;
  const double used = solver.state().stable_step;
  ASSERT_GT(calibrated, 0.0);
  // The element estimate alone is 2-3x below; the calibration lifts it.
  EXPECT_GT(solver.state().step_calibration, 1.5);

  // The measured limit: bisect the fixed step between stable and blowing up within 400 steps.
  const int steps = 400;
  double stable = 0.9 * calibrated, unstable = 1.1 * calibrated;
  ASSERT_FALSE(blows_up(stable, steps)) << "0.9 x calibrated must be stable";
  ASSERT_TRUE(blows_up(unstable, steps)) << "1.1 x calibrated must blow up";
  for (int i = 0; i < 8; ++i) {
    const double mid = 0.5 * (stable + unstable);
    (blows_up(mid, steps) ? unstable : stable) = mid;
  }
  const double limit = 0.5 * (stable + unstable);
  std::printf("stable step: calibrated 2/omega_max %.5g s, measured limit %.5g s (%.4f x), used %.5g s "
              "(%.3f of the limit), element estimate x%.2f below\n",
              calibrated, limit, limit / calibrated, used, used / limit, solver.state().step_calibration);
  EXPECT_LT(used, limit) << "the step used must be stable";
  EXPECT_GT(used, 0.78 * limit) << "and within ~20 % of the measured instability limit";
  EXPECT_NEAR(limit, calibrated, 0.03 * calibrated);

  // The run at the step used stays bounded. (Its energy balance is no test here: at omega dt
  // = 1.6 the integer-step kinetic energy of the top mode is off by ~(omega dt)^2 / 4.)
  solver.advance_window(2000 * used);
  EXPECT_LT(solver.state().velocity.cwiseAbs().maxCoeff(), 1e-5);
}

}  // namespace
}  // namespace valvefsi::solid::testing
