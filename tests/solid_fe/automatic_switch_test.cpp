// The automatic explicit -> implicit switch (solid.time_integration: AUTOMATIC, docs/solid_fe.md
// "Automatic switch") on the pressed flap: an MHGO strip clamped on one side, pushed by 10 kPa onto
// a plane 0.3 mm below (mass damping 300/s), released at 60 ms. AUTOMATIC switches to implicit
// while the flap lies pressed and back to explicit at the release, its states agree with the
// explicit run's, in far fewer steps; restarts before the first switch and in the implicit phase
// continue bit for bit across the next switch.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "test_meshes.hpp"
#include "valvefsi/solid/shell_solver.hpp"
#include "valvefsi/solid/solver_restart.hpp"

namespace valvefsi::solid {
namespace {

using testing::rectangular_plate;

constexpr double kThickness = 0.25e-3;
constexpr double kRelease = 60e-3, kEnd = 75e-3;  // s
constexpr int kWindows = 75;  // 1 ms output windows to kEnd

// Pressed from 0 (ramp over 1 ms), released over 1 ms from 60 ms: the load's sign changes at 61 ms.
double pressure(double t) {
  if (t < kRelease) return -10e3 * std::min(1.0, t / 1e-3);
  return -10e3 * std::max(0.0, 1.0 - (t - kRelease) / 1e-3);
}

std::unique_ptr<ShellSolver> flap(TimeIntegration integration,
                                  double settled_filter_time = SolverOptions{}.settled_filter_time,
                                  double time_step_safety = SolverOptions{}.time_step_safety,
                                  double implicit_tangent_cost = 0.0, double max_time_step = 1e-3) {
  Mesh mesh = rectangular_plate(0.01, 0.005, 10, 5, kThickness);
  ShellModelOptions options;
  options.fixed_nodes = mesh.node_sets.at("left");
  SolverOptions o = testing::pressed_flap_options();
  o.max_energy_balance_error = 0.2;
  o.time_integration = integration;
  o.implicit_initial_step = 1e-6;
  o.max_time_step = max_time_step;
  o.implicit_tangent_cost = implicit_tangent_cost;
  o.settled_filter_time = settled_filter_time;
  o.time_step_safety = time_step_safety;
  auto solver = std::make_unique<ShellSolver>(build_shell_model(mesh, options), Material{Mhgo{}}, o);
  solver->set_pressure(pressure);
  solver->add_contact_plane({Eigen::Vector3d(0, 0, -0.3e-3), Eigen::Vector3d(0, 0, 1)});
  return solver;
}

struct FlapRun {
  Eigen::Matrix3Xd pressed, released;  // positions at kRelease and kEnd
  std::vector<std::int64_t> steps_at_ms;       // steps taken by the end of each 1 ms window
  std::vector<double> switch_times;    // AUTOMATIC: the times its phase changed
  std::int64_t cost_switches = 0;      // AUTOMATIC: back to explicit by the cost rule
  std::int64_t implicit_steps = 0;     // AUTOMATIC: steps taken in the implicit phase
};

FlapRun run_flap(TimeIntegration integration, double settled_filter_time = SolverOptions{}.settled_filter_time,
                 double time_step_safety = SolverOptions{}.time_step_safety, double implicit_tangent_cost = 0.0,
                 double max_time_step = 1e-3) {
  auto solver = flap(integration, settled_filter_time, time_step_safety, implicit_tangent_cost, max_time_step);
  FlapRun r;
  bool phase = false;
  solver->set_step_observer([&](const SolverState& s) {
    if (s.implicit_phase != phase) r.switch_times.push_back(s.time);
    phase = s.implicit_phase;
    if (s.implicit_phase) ++r.implicit_steps;
  });
  for (int k = 1; k <= kWindows; ++k) {
    solver->advance_window(k * 1e-3);
    r.steps_at_ms.push_back(solver->state().step);
    if (k == 60) r.pressed = solver->state().position;
  }
  r.released = solver->state().position;
  r.cost_switches = solver->state().cost_switches;
  std::printf("%s: %lld steps, %lld switches, balance %.3g of the largest energy, numerical dissipation %.3g J\n",
              integration == TimeIntegration::automatic ? "automatic" : "explicit",
              static_cast<long long>(solver->state().step), static_cast<long long>(solver->state().switches),
              solver->state().energy.balance_error_of_largest(), solver->state().energy.numerical_dissipation);
  return r;
}

// Bound: both runs settle onto the same static state and release from it; they differ by what
// each leaves unsettled (the implicit-only run: 2.3 um, 0.9 % of the thickness). 2 % of the
// thickness (5 um) is 60x below the 0.3 mm travel.
// (The instantaneous kinetic energy: settled_filter_time = 0, the default.)
TEST(AutomaticSwitch, PressedFlapSwitchesToImplicitAndBackWhenReleasedAndAgreesWithExplicit) {
  const FlapRun automatic = run_flap(TimeIntegration::automatic, 0.0);
  const FlapRun reference = run_flap(TimeIntegration::explicit_central_difference);
  for (double t : automatic.switch_times) std::printf("  switch at %.4f ms\n", 1e3 * t);
  ASSERT_GE(automatic.switch_times.size(), 2u);
  // To implicit once settled for 5 ms while pressed; back to explicit when the load changes sign.
  EXPECT_GT(automatic.switch_times[0], 5e-3);
  EXPECT_LT(automatic.switch_times[0], kRelease);
  EXPECT_GE(automatic.switch_times[1], kRelease);
  EXPECT_LE(automatic.switch_times[1], kRelease + 1e-3 + 1e-9);
  const double pressed = (automatic.pressed - reference.pressed).colwise().norm().maxCoeff();
  const double released = (automatic.released - reference.released).colwise().norm().maxCoeff();
  const double travel = (reference.released - reference.pressed).colwise().norm().maxCoeff();
  // Steps over the pressed span AUTOMATIC took implicitly (from the first whole ms after the
  // switch to the release) and over the whole run.
  const auto first = static_cast<std::size_t>(std::ceil(1e3 * automatic.switch_times[0]));
  const auto span = [&](const FlapRun& r) { return r.steps_at_ms[59] - r.steps_at_ms[first - 1]; };
  const std::int64_t total = automatic.steps_at_ms.back(), reference_total = reference.steps_at_ms.back();
  std::printf("explicit run's largest travel after the release %.3g m; steps %zu-60 ms %lld vs %lld, 0-75 ms %lld vs "
              "%lld\n", travel, first, static_cast<long long>(span(automatic)), static_cast<long long>(span(reference)),
              static_cast<long long>(total), static_cast<long long>(reference_total));
  std::printf("largest node distance automatic vs explicit: pressed %.3g m, released %.3g m (%.3g / %.3g of the "
              "thickness)\n", pressed, released, pressed / kThickness, released / kThickness);
  EXPECT_LT(pressed, 0.02 * kThickness);
  EXPECT_LT(released, 0.02 * kThickness);
  EXPECT_LT(span(automatic), span(reference) / 5);  // (measured 232 vs 1848: contact chatter keeps Newton slow)
  EXPECT_LT(total, reference_total);
}

// The switches on the kinetic energy of the velocity low-pass filtered over 1 ms: the pressed
// flap's contact chatter (instantaneous kinetic energy above 5 % of the strain energy until ~22 ms)
// is much faster than 1 ms, so the flap counts as settled as soon as it lies still on the plane.
// All three runs take half the default explicit step (time_step_safety 0.4), so that the released
// state compares the switch, not the explicit step error (below).
TEST(AutomaticSwitch, FilteredKineticEnergySwitchesEarlierWithTheSameAnswer) {
  constexpr double kSafety = 0.4;
  const FlapRun filtered = run_flap(TimeIntegration::automatic, 1e-3, kSafety);
  const FlapRun instantaneous = run_flap(TimeIntegration::automatic, 0.0, kSafety);
  const FlapRun reference = run_flap(TimeIntegration::explicit_central_difference, 0.0, kSafety);
  for (double t : filtered.switch_times) std::printf("  filtered: switch at %.4f ms\n", 1e3 * t);
  ASSERT_GE(filtered.switch_times.size(), 2u);
  ASSERT_GE(instantaneous.switch_times.size(), 2u);
  const double pressed = (filtered.pressed - reference.pressed).colwise().norm().maxCoeff();
  const double released = (filtered.released - reference.released).colwise().norm().maxCoeff();
  const double released_instantaneous = (instantaneous.released - reference.released).colwise().norm().maxCoeff();
  std::printf("filtered vs explicit: pressed %.3g m, released %.3g m (%.3g / %.3g of the thickness; instantaneous "
              "switch released %.3g m); steps %lld (instantaneous %lld, explicit %lld)\n", pressed, released,
              pressed / kThickness, released / kThickness, released_instantaneous,
              static_cast<long long>(filtered.steps_at_ms.back()), static_cast<long long>(instantaneous.steps_at_ms.back()),
              static_cast<long long>(reference.steps_at_ms.back()));
  // Implicit 5 ms after the flap lies still (measured 7.15 ms; instantaneous 26.88 ms). It may come
  // back to explicit while pressed when the instantaneous energy rises again after the implicit
  // scheme had damped it (measured: 16.13 -> 21.14 ms), but the last switch is the release's,
  // caught as early as without the filter (measured 60.09 ms).
  EXPECT_GT(filtered.switch_times[0], 5e-3);
  EXPECT_LT(filtered.switch_times[0], instantaneous.switch_times[0] - 10e-3);
  EXPECT_EQ(filtered.switch_times.size() % 2, 0u);
  EXPECT_LT(filtered.switch_times[filtered.switch_times.size() - 2], kRelease);
  EXPECT_GE(filtered.switch_times.back(), kRelease);
  // Within a microsecond: the back-switch is seen after an implicit step, and since the twentieth
  // session's kept-tangent rules the two runs' steps near the release differ (measured 60.0949 ms
  // against 60.0945 ms; before, equal to 1e-9).
  EXPECT_LE(filtered.switch_times.back(), instantaneous.switch_times[1] + 1e-6);
  // Bounds: 2 % of the thickness pressed (as above; measured 0.024 um). Released 1 % (2.5 um;
  // measured 0.49 um, the instantaneous switch 0.66 um), 160x below the 0.41 mm travel. Why half the
  // step: after the release every run integrates explicitly, and at the default safety 0.8 the
  // explicit step error is what the comparison sees. The explicit run itself moves 27.5 um at
  // 75 ms when its step is halved (then 6.1 and 1.5 um per further halving: second order), and
  // at 0.8 the filtered run's difference (5.0 um; instantaneous 3.4 um) scatters over 2.7-5.9 um
  // when the Newton tolerance (1e-6 to 1e-10), the implicit step cap (1 ms to 20 us) or rho_inf
  // (0.5 to 1) change, converging with none of them; with the step it falls (0.49 um at 0.4; at
  // 0.2 the filtered run is 0.24 um from the explicit run at 0.1). docs/solid_fe.md, "The
  // filtered switch's test bound".
  EXPECT_LT(pressed, 0.02 * kThickness);
  EXPECT_LT(released, 0.01 * kThickness);
  EXPECT_LT(released_instantaneous, 0.01 * kThickness);
  EXPECT_LT(filtered.steps_at_ms.back(), instantaneous.steps_at_ms.back());
}

// The cost rule (implicit_tangent_cost): an implicit phase whose block of 16 steps costs more
// force evaluations and tangents than the explicit steps over the same time, and whose step did
// not grow, goes back to explicit. Priced at 1 explicit step per tangent, same cost, two cases.
// Large implicit steps (the pressed flap with the instantaneous switch, implicit from 27 ms): the
// rule may send a block that still chatters back (measured 27.7 and 35.1 ms), but once the flap
// lies still its large steps pay and the last implicit phase runs to the release (measured
// 40.2-60.1 ms). Tiny ones (the flap with the 1 ms filter and every step capped at 8 us, so an
// implicit step is no longer than an explicit one and costs at least two force evaluations): each
// try ends after the ramp block and one judged block (measured 10 tries, 322 implicit steps
// against 6,200 unpriced), and the run keeps the explicit run's answer.
double longest_implicit_phase(const FlapRun& r, double end) {
  double longest = 0.0;
  for (std::size_t k = 0; k < r.switch_times.size(); k += 2) {
    const double until = k + 1 < r.switch_times.size() ? r.switch_times[k + 1] : end;
    longest = std::max(longest, until - r.switch_times[k]);
  }
  return longest;
}

TEST(AutomaticSwitch, CostRuleKeepsLargeImplicitStepsAndRefusesTinyOnes) {
  constexpr double kCost = 1.0;
  const FlapRun large = run_flap(TimeIntegration::automatic, 0.0, SolverOptions{}.time_step_safety, kCost);
  const FlapRun large_reference = run_flap(TimeIntegration::explicit_central_difference);
  for (double t : large.switch_times) std::printf("  large steps, priced: switch at %.4f ms\n", 1e3 * t);
  const double large_released = (large.released - large_reference.released).colwise().norm().maxCoeff();
  std::printf("large steps: cost switches %lld, longest implicit phase %.2f ms, released vs explicit %.3g m\n",
              static_cast<long long>(large.cost_switches), 1e3 * longest_implicit_phase(large, kEnd), large_released);
  ASSERT_GE(large.switch_times.size(), 2u);
  EXPECT_GE(large.switch_times.back(), kRelease);  // the last phase ends at the release, not by the rule
  EXPECT_GT(longest_implicit_phase(large, kEnd), 15e-3);
  EXPECT_LT(large_released, 0.02 * kThickness);

  constexpr double kTinyStep = 8e-6;
  const FlapRun tiny_plain = run_flap(TimeIntegration::automatic, 1e-3, SolverOptions{}.time_step_safety, 0.0, kTinyStep);
  const FlapRun tiny = run_flap(TimeIntegration::automatic, 1e-3, SolverOptions{}.time_step_safety, kCost, kTinyStep);
  const FlapRun reference = run_flap(TimeIntegration::explicit_central_difference, 0.0, SolverOptions{}.time_step_safety,
                                     0.0, kTinyStep);
  const double released = (tiny.released - reference.released).colwise().norm().maxCoeff();
  std::printf("tiny steps: cost switches %lld, longest implicit phase %.3f ms (unpriced %.2f ms), implicit steps %lld "
              "(unpriced %lld), released vs explicit %.3g m\n", static_cast<long long>(tiny.cost_switches),
              1e3 * longest_implicit_phase(tiny, kEnd), 1e3 * longest_implicit_phase(tiny_plain, kEnd),
              static_cast<long long>(tiny.implicit_steps), static_cast<long long>(tiny_plain.implicit_steps), released);
  EXPECT_EQ(tiny_plain.cost_switches, 0);
  EXPECT_GE(tiny.cost_switches, 2);
  EXPECT_LT(longest_implicit_phase(tiny, kEnd), 1e-3);
  EXPECT_GT(longest_implicit_phase(tiny_plain, kEnd), 15e-3);
  EXPECT_LT(tiny.implicit_steps, tiny_plain.implicit_steps / 4);
  EXPECT_LT(released, 0.02 * kThickness);
}

// With the instantaneous and with the filtered switch: a restart written before the first switch
// (explicit phase) and one written in the implicit phase continue bit for bit across the next
// switch: the file holds the switch state (the filtered velocity too) and the
// acceleration, and the uninterrupted run drops its kept tangent at the restart points as the
// continued one starts without it.
TEST(AutomaticSwitch, RestartsContinueBitForBitAcrossTheSwitch) {
  const auto dir = std::filesystem::temp_directory_path() / "solid_automatic_switch_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::vector<int> restart_ms = {4, 40};
  for (const double filter : {0.0, 1e-3}) {  // the instantaneous and the filtered switch
    std::printf("settled_filter_time %g s\n", filter);
    auto solver = flap(TimeIntegration::automatic, filter);
    std::vector<bool> implicit_at_restart;
    for (int k = 1; k <= kWindows; ++k) {
      solver->advance_window(k * 1e-3);
      if (std::find(restart_ms.begin(), restart_ms.end(), k) != restart_ms.end()) {
        write_solver_restart(*solver, dir / ("restart-" + std::to_string(k) + ".h5"));
        solver->drop_kept_tangent();
        implicit_at_restart.push_back(solver->state().implicit_phase);
      }
    }
    EXPECT_FALSE(implicit_at_restart[0]) << "the first restart is meant to precede the switch";
    EXPECT_TRUE(implicit_at_restart[1]) << "the second restart is meant to lie in the implicit phase";
    for (int start : restart_ms) {
      auto continued = flap(TimeIntegration::automatic, filter);
      continued->advance_window(0.0);
      read_solver_restart(dir / ("restart-" + std::to_string(start) + ".h5"), *continued);
      for (int k = start + 1; k <= kWindows; ++k) {
        continued->advance_window(k * 1e-3);
        if (k == 40 && start < 40) continued->drop_kept_tangent();  // the uninterrupted run's restart point
      }
      const SolverState& a = solver->state();
      const SolverState& b = continued->state();
      std::printf("restart at %d ms: steps %lld vs %lld, switches %lld vs %lld, largest position difference %.3g m\n",
                  start, static_cast<long long>(b.step), static_cast<long long>(a.step),
                  static_cast<long long>(b.switches), static_cast<long long>(a.switches),
                  (a.position - b.position).cwiseAbs().maxCoeff());
      EXPECT_EQ(b.step, a.step);
      EXPECT_EQ(b.switches, a.switches);
      EXPECT_GE(a.switches, 2);
      EXPECT_TRUE(b.position == a.position) << "restart at " << start << " ms";
      EXPECT_TRUE(b.velocity == a.velocity) << "restart at " << start << " ms";
      EXPECT_EQ(b.energy.numerical_dissipation, a.energy.numerical_dissipation);
    }
  }
}

}  // namespace
}  // namespace valvefsi::solid
