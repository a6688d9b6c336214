// Model problems against their analytic coupling limits: the incompressible piston (added-mass
// limit of constant relaxation) and the acoustic piston (serial/parallel explicit limits in
// mu = rho_f c dt / (rho_s h_s); implicit IQN-ILS beyond them).
#include "valvefsi/coupling/model_problems/acoustic_column_fluid.hpp"
#include "valvefsi/coupling/model_problems/in_process_coupling.hpp"
#include "valvefsi/coupling/model_problems/incompressible_piston_fluid.hpp"
#include "valvefsi/coupling/model_problems/nonlinear_fixed_point.hpp"
#include "valvefsi/coupling/model_problems/piston_solid.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <iostream>
#include <stdexcept>
#include <utility>
#include <vector>

namespace valvefsi::coupling::model {
namespace {

AccelerationOptions acceleration(AccelerationKind kind, double omega) {
  AccelerationOptions o;
  o.kind = kind;
  o.relaxation = omega;
  return o;
}

// ---------------------------------------------------------------- incompressible piston
struct IncompressiblePiston {
  double structure_mass = 0.004;  // kg
  double stiffness = 0.0;         // N/m
  double external_force = 0.1;    // N
  double window = 1e-3;           // s
  IncompressiblePistonFluidParameters fluid_parameters;  // rho 1000, L 0.1 m, A 1 cm^2: m_a = 0.01 kg

  double added_mass() const { return IncompressiblePistonFluid(fluid_parameters).added_mass(); }
  double initial_acceleration() const {
    return (external_force - fluid_parameters.area * fluid_parameters.far_end_pressure) / (structure_mass + added_mass());
  }
  CouplingRun run(const AccelerationOptions& accel, int windows, int max_iterations) const {
    IncompressiblePistonFluidParameters f = fluid_parameters;
    f.initial_acceleration = initial_acceleration();
    PistonSolidParameters s;
    s.mass = structure_mass;
    s.stiffness = stiffness;
    s.external_force = external_force;
    s.initial_acceleration = initial_acceleration();
    IncompressiblePistonFluid fluid(f);
    PistonSolid solid(s);
    CouplingLoopOptions options;
    options.scheme = CouplingScheme::implicit;
    options.window = window;
    options.windows = windows;
    options.acceleration = accel;
    options.tolerance = 1e-10;
    options.max_iterations = max_iterations;
    return run_in_process(fluid, solid, options);
  }
  double relaxation_limit() const {
    return incompressible_piston_relaxation_limit(added_mass(), structure_mass, stiffness, 0.25, window);
  }
};

TEST(IncompressiblePiston, ConstantRelaxationConvergesJustBelowTwoOverOnePlusMassRatioOnly) {
  const IncompressiblePiston piston;  // m_a / m_s = 2.5: omega < 2 / 3.5
  ASSERT_NEAR(piston.added_mass(), 0.01, 1e-15);
  ASSERT_NEAR(piston.relaxation_limit(), 2.0 / 3.5, 1e-15);
  const double limit = piston.relaxation_limit();

  const CouplingRun below = piston.run(acceleration(AccelerationKind::constant_relaxation, 0.97 * limit), 5, 3000);
  ASSERT_TRUE(below.all_windows_converged);
  // Converged, the pair is the monolithic piston of mass m_s + m_a: constant acceleration, which
  // the trapezoidal rule integrates exactly.
  const double a = piston.initial_acceleration();
  const double t = below.windows.back().time;
  EXPECT_NEAR(below.windows.back().motion(0), 0.5 * a * t * t, 1e-9 * 0.5 * a * t * t);
  EXPECT_NEAR(below.windows.back().motion(1), a * t, 1e-9 * a * t);
  std::cout << "[ incompressible ] omega = 0.97 limit: " << below.windows.front().iterations << " iterations in window 1\n";

  const CouplingRun above = piston.run(acceleration(AccelerationKind::constant_relaxation, 1.03 * limit), 5, 3000);
  EXPECT_FALSE(above.all_windows_converged);
  EXPECT_GT(above.windows.front().residual, 1.0);  // the iteration grew, it did not merely stall
}

TEST(IncompressiblePiston, TheSpringRaisesTheLimitAsDerived) {
  // With k, the structure's effective mass per window is m_s + beta k dt^2.
  IncompressiblePiston piston;
  piston.stiffness = piston.structure_mass / (0.25 * piston.window * piston.window);  // doubles it
  const double limit = piston.relaxation_limit();
  ASSERT_NEAR(limit, 2.0 / (1.0 + 0.01 / 0.008), 1e-12);
  EXPECT_TRUE(piston.run(acceleration(AccelerationKind::constant_relaxation, 0.97 * limit), 3, 3000).all_windows_converged);
  EXPECT_FALSE(piston.run(acceleration(AccelerationKind::constant_relaxation, 1.03 * limit), 3, 3000).all_windows_converged);
}

TEST(IncompressiblePiston, IqnIlsConvergesAtAHundredfoldAddedMassToTheMonolithicSolution) {
  IncompressiblePiston piston;
  piston.structure_mass = 1e-4;  // m_a / m_s = 100: constant relaxation would need omega < 0.0198
  piston.stiffness = 50.0;
  {
    const CouplingRun run = piston.run(acceleration(AccelerationKind::iqn_ils, 0.01), 40, 100);
    ASSERT_TRUE(run.all_windows_converged);
    int most = 0;
    for (const auto& w : run.windows) most = std::max(most, w.iterations);
    std::cout << "[ incompressible ] m_a/m_s = 100, IQN-ILS: at most " << most << " iterations per window\n";
    // Two unknowns [u, v]: exact arithmetic needs n + 2 = 4 evaluations; allow one for round-off
    // (dv/du = 2 m_a / (m_s dt) = 2e5 here amplifies it at the 1e-10 tolerance).
    EXPECT_LE(most, 5);
    // The converged pair is the monolithic Newmark solution of (m_s + m_a) a + k u = F.
    PistonSolidParameters monolithic;
    monolithic.mass = piston.structure_mass + piston.added_mass();
    monolithic.stiffness = piston.stiffness;
    monolithic.external_force = piston.external_force;
    monolithic.initial_acceleration = piston.initial_acceleration();
    PistonSolid reference(monolithic);
    for (const auto& w : run.windows) {
      const Eigen::VectorXd expected = reference.advance(piston.window, Eigen::VectorXd::Zero(1));
      ASSERT_NEAR(w.motion(0), expected(0), 1e-8 * std::abs(expected(0)) + 1e-15);
      ASSERT_NEAR(w.motion(1), expected(1), 1e-8 * std::abs(expected(1)) + 1e-12);
    }
  }
}

// ---------------------------------------------------------------- acoustic piston
struct AcousticPiston {
  double mu = 1.0;          // rho_f c dt / (rho_s h_s)
  double cfl = 1.0;
  FarEnd far_end = FarEnd::non_reflecting;
  double drive_pressure = 100.0;  // Pa behind the piston
  AcousticColumnParameters column;  // rho 1000, c 10 m/s, L 0.1 m, 100 cells, A 1 m^2

  double window() const { return cfl * column.column_length / column.cells / column.sound_speed; }
  double terminal_velocity() const { return drive_pressure / (column.density * column.sound_speed); }
  CouplingRun run(CouplingScheme scheme, int windows, const AccelerationOptions& accel = {},
                  int max_iterations = 200) const {
    AcousticColumnParameters c = column;
    c.far_end = far_end;
    PistonSolidParameters s;
    s.mass = column.density * column.sound_speed * window() / mu;  // per m^2
    s.external_force = drive_pressure * column.area;
    s.initial_acceleration = s.external_force / s.mass;  // the fluid is at rest: no force yet
    AcousticColumnFluid fluid(c);
    PistonSolid solid(s);
    CouplingLoopOptions options;
    options.scheme = scheme;
    options.window = window();
    options.windows = windows;
    options.acceleration = accel;
    options.tolerance = 1e-12;
    options.max_iterations = max_iterations;
    options.divergence_bound = 1e3;
    return run_in_process(fluid, solid, options);
  }
};

TEST(AcousticColumn, CarriesThePistonPulseAtTheSoundSpeedAndReflectsIt) {
  // A piston held at v = 1 cm/s: p = rho c v behind the front x = c t; with CFL = 1 upwinding is exact.
  for (const FarEnd end : {FarEnd::non_reflecting, FarEnd::closed}) {
    AcousticColumnParameters p;
    p.far_end = end;
    AcousticColumnFluid column(p);
    const double v = 0.01, dt = column.cell_size() / p.sound_speed;
    Eigen::VectorXd force;
    for (int n = 0; n < 40; ++n) force = column.advance(dt, Eigen::Vector2d(0.0, v));
    const double rho_c_v = p.density * p.sound_speed * v;
    EXPECT_NEAR(force(0), -rho_c_v * p.area, 1e-12);
    EXPECT_NEAR(column.pressure()(39), rho_c_v, 1e-12);
    EXPECT_NEAR(column.pressure()(40), 0.0, 1e-12);
    EXPECT_NEAR(column.velocity()(10), v, 1e-15);
    for (int n = 40; n < 150; ++n) column.advance(dt, Eigen::Vector2d(0.0, v));
    // After 1.5 transits the reflected front is half way back: a closed end doubles the pressure behind it.
    const double expected_near_end = end == FarEnd::closed ? 2.0 * rho_c_v : rho_c_v;
    EXPECT_NEAR(column.pressure()(90), expected_near_end, 1e-9);
    EXPECT_NEAR(column.pressure()(10), rho_c_v, 1e-9);
  }
}

TEST(AcousticPiston, SerialExplicitIsStableJustBelowMuTwoAndDivergesJustAbove) {
  const AcousticPistonLimits limits;
  for (const double cfl : {1.0, 0.5}) {  // the limit is in mu, independent of the mesh
    AcousticPiston piston;
    piston.cfl = cfl;
    piston.mu = 0.97 * limits.serial_explicit;
    const CouplingRun stable = piston.run(CouplingScheme::serial_explicit, 3000);
    ASSERT_FALSE(stable.diverged) << "cfl " << cfl;
    // It reaches the radiation-damped terminal velocity v = p_drive / (rho c).
    EXPECT_NEAR(stable.windows.back().motion(1), piston.terminal_velocity(), 1e-6 * piston.terminal_velocity());

    piston.mu = 1.03 * limits.serial_explicit;
    const CouplingRun unstable = piston.run(CouplingScheme::serial_explicit, 3000);
    EXPECT_TRUE(unstable.diverged) << "cfl " << cfl;
    std::cout << "[ acoustic ] serial explicit, CFL " << cfl << ": mu = 1.94 stable, mu = 2.06 diverged after "
              << unstable.windows.size() << " windows\n";
  }
}

TEST(AcousticPiston, ParallelExplicitFailsEarlierAtTwoRootTwoMinusTwo) {
  const AcousticPistonLimits limits;
  ASSERT_NEAR(limits.parallel_explicit, 2.0 * (std::sqrt(2.0) - 1.0), 1e-15);
  AcousticPiston piston;
  piston.mu = 0.97 * limits.parallel_explicit;
  const CouplingRun stable = piston.run(CouplingScheme::parallel_explicit, 4000);
  ASSERT_FALSE(stable.diverged);
  EXPECT_NEAR(stable.windows.back().motion(1), piston.terminal_velocity(), 1e-6 * piston.terminal_velocity());
  piston.mu = 1.03 * limits.parallel_explicit;
  EXPECT_TRUE(piston.run(CouplingScheme::parallel_explicit, 4000).diverged);
  piston.mu = 1.5;  // serial explicit is fine here
  EXPECT_TRUE(piston.run(CouplingScheme::parallel_explicit, 4000).diverged);
  EXPECT_FALSE(piston.run(CouplingScheme::serial_explicit, 4000).diverged);
}

TEST(AcousticPiston, ImplicitIqnIlsAndAitkenConvergeBelowAndFarAboveTheExplicitLimits) {
  for (const auto kind : {AccelerationKind::iqn_ils, AccelerationKind::aitken}) {
    for (const double mu : {1.5, 2.5, 10.0, 100.0}) {
      AcousticPiston piston;
      piston.mu = mu;
      const CouplingRun run = piston.run(CouplingScheme::implicit, 1500, acceleration(kind, 0.1));
      ASSERT_TRUE(run.all_windows_converged) << "mu " << mu;
      ASSERT_FALSE(run.diverged) << "mu " << mu;
      int most = 0;
      for (const auto& w : run.windows) most = std::max(most, w.iterations);
      std::cout << "[ acoustic ] implicit " << (kind == AccelerationKind::aitken ? "Aitken" : "IQN-ILS") << ", mu = " << mu
                << ": at most " << most << " iterations per window\n";
      EXPECT_LE(most, kind == AccelerationKind::iqn_ils ? 4 : 20) << "mu " << mu;
      EXPECT_NEAR(run.windows.back().motion(1), piston.terminal_velocity(), 1e-6 * piston.terminal_velocity());
    }
  }
}

TEST(AcousticPiston, TrajectoriesFollowTheAnalysedRecurrences) {
  // The stability limits above are derived from these scalar recurrences (m'' per area, a in
  // m/s^2): serial explicit a_{n+1} = (p_d - rho c v_n) / m'', parallel explicit uses v_{n-1},
  // converged implicit v_{n+1}; all with v_{n+1} = v_n + dt/2 (a_n + a_{n+1}).
  AcousticPiston piston;
  piston.mu = 0.7;  // stable for all three
  const double dt = piston.window(), rho_c = piston.column.density * piston.column.sound_speed;
  const double mass = rho_c * dt / piston.mu;
  const auto recurrence = [&](int lag, int windows) {  // lag: 0 implicit, 1 serial, 2 parallel
    std::vector<double> v(static_cast<std::size_t>(windows) + 1, 0.0);
    double a = piston.drive_pressure / mass;
    for (int n = 0; n < windows; ++n) {
      const int seen = n + 1 - lag;
      double a_next;
      if (lag == 0) {  // solve v_{n+1} = v_n + dt/2 (a + (p_d - rho c v_{n+1}) / m'')
        const double v_next = (v[static_cast<std::size_t>(n)] + 0.5 * dt * (a + piston.drive_pressure / mass)) /
                              (1.0 + 0.5 * dt * rho_c / mass);
        a_next = (piston.drive_pressure - rho_c * v_next) / mass;
      } else {
        a_next = (piston.drive_pressure - rho_c * (seen >= 0 ? v[static_cast<std::size_t>(seen)] : 0.0)) / mass;
      }
      v[static_cast<std::size_t>(n) + 1] = v[static_cast<std::size_t>(n)] + 0.5 * dt * (a + a_next);
      a = a_next;
    }
    return v;
  };
  const std::vector<std::pair<CouplingScheme, int>> schemes = {
      {CouplingScheme::implicit, 0}, {CouplingScheme::serial_explicit, 1}, {CouplingScheme::parallel_explicit, 2}};
  for (const auto& [scheme, lag] : schemes) {
    const CouplingRun run = piston.run(scheme, 200, acceleration(AccelerationKind::iqn_ils, 0.1));
    const std::vector<double> expected = recurrence(lag, 200);
    ASSERT_EQ(run.windows.size(), 200u);
    for (std::size_t n = 0; n < run.windows.size(); ++n) {
      ASSERT_NEAR(run.windows[n].motion(1), expected[n + 1], 1e-9 * piston.terminal_velocity()) << "lag " << lag << " window " << n;
    }
  }
}

TEST(AcousticPiston, IqnIlsReusingPastWindowsNeedsFewerIterations) {
  // The window map is affine with the same Jacobian every window: kept columns make the first
  // quasi-Newton update of a new window exact.
  AcousticPiston piston;
  piston.mu = 10.0;
  AccelerationOptions reuse = acceleration(AccelerationKind::iqn_ils, 0.1);
  reuse.reused_windows = 2;
  const CouplingRun fresh = piston.run(CouplingScheme::implicit, 300, acceleration(AccelerationKind::iqn_ils, 0.1));
  const CouplingRun reused = piston.run(CouplingScheme::implicit, 300, reuse);
  ASSERT_TRUE(fresh.all_windows_converged && reused.all_windows_converged);
  int fresh_total = 0, reused_total = 0, reused_most_after_first = 0;
  for (std::size_t n = 0; n < fresh.windows.size(); ++n) {
    fresh_total += fresh.windows[n].iterations;
    reused_total += reused.windows[n].iterations;
    if (n > 0) reused_most_after_first = std::max(reused_most_after_first, reused.windows[n].iterations);
  }
  std::cout << "[ acoustic ] IQN-ILS mu = 10, 300 windows: " << fresh_total << " iterations without reuse, "
            << reused_total << " with reused_windows = 2\n";
  EXPECT_LE(reused_most_after_first, 3);
  EXPECT_LT(reused_total, fresh_total);
  EXPECT_NEAR(reused.windows.back().motion(1), fresh.windows.back().motion(1), 1e-9 * piston.terminal_velocity());
}

TEST(AcousticPiston, UnrelaxedImplicitIterationConvergesOnlyBelowMuTwo) {
  const AcousticPistonLimits limits;
  AcousticPiston piston;
  // The iteration error shrinks by mu/2 per iteration: 0.95 needs ~540 iterations for 1e-12.
  const auto unrelaxed = acceleration(AccelerationKind::constant_relaxation, 1.0);
  piston.mu = 0.95 * limits.implicit_without_relaxation;
  EXPECT_TRUE(piston.run(CouplingScheme::implicit, 20, unrelaxed, 2000).all_windows_converged);
  piston.mu = 1.05 * limits.implicit_without_relaxation;
  EXPECT_FALSE(piston.run(CouplingScheme::implicit, 20, unrelaxed, 2000).all_windows_converged);
}

TEST(AcousticPiston, AClosedColumnKeepsTheSerialLimit) {
  // Reflections return the piston's own waves (damped by upwinding); the local limit still decides.
  AcousticPiston piston;
  piston.far_end = FarEnd::closed;
  piston.cfl = 0.8;
  piston.mu = 0.95 * AcousticPistonLimits{}.serial_explicit;
  const CouplingRun stable = piston.run(CouplingScheme::serial_explicit, 6000);  // 48 transits
  EXPECT_FALSE(stable.diverged);
  piston.mu = 1.05 * AcousticPistonLimits{}.serial_explicit;
  EXPECT_TRUE(piston.run(CouplingScheme::serial_explicit, 6000).diverged);
}

// ---------------------------------------------------------------- nonlinear fixed point
TEST(NonlinearFixedPoint, IqnIlsFindsTheRootWherePlainIterationDiverges) {
  const NonlinearFixedPoint problem = NonlinearFixedPoint::standard();
  const Eigen::VectorXcd eigenvalues = problem.jacobian_at_root().eigenvalues();
  ASSERT_GT(eigenvalues.cwiseAbs().maxCoeff(), 2.0);  // non-contractive

  CouplingLoopOptions options;
  options.scheme = CouplingScheme::implicit;
  options.windows = 1;
  options.tolerance = 1e-12;
  options.max_iterations = 200;
  options.acceleration = acceleration(AccelerationKind::constant_relaxation, 1.0);
  NonlinearFixedPointFluid fluid(problem);
  NonlinearFixedPointSolid solid(problem);
  EXPECT_FALSE(run_in_process(fluid, solid, options).all_windows_converged);

  options.acceleration = acceleration(AccelerationKind::iqn_ils, 0.1);
  NonlinearFixedPointFluid fluid2(problem);
  NonlinearFixedPointSolid solid2(problem);
  const CouplingRun run = run_in_process(fluid2, solid2, options);
  ASSERT_TRUE(run.all_windows_converged);
  std::cout << "[ nonlinear ] IQN-ILS: " << run.windows.front().iterations << " iterations\n";
  EXPECT_LE(run.windows.front().iterations, 20);
  EXPECT_LT((run.windows.front().motion - problem.root).norm(), 1e-10);
}

TEST(ModelProblems, ParsingAndParameterErrors) {
  EXPECT_EQ(parse_coupling_scheme("serial-explicit"), CouplingScheme::serial_explicit);
  EXPECT_EQ(parse_coupling_scheme("parallel-explicit"), CouplingScheme::parallel_explicit);
  EXPECT_EQ(parse_coupling_scheme("implicit"), CouplingScheme::implicit);
  EXPECT_THROW(parse_coupling_scheme("staggered"), std::invalid_argument);
  EXPECT_EQ(parse_far_end("closed"), FarEnd::closed);
  EXPECT_THROW(parse_far_end("wall"), std::invalid_argument);
  PistonSolidParameters bad;
  bad.mass = -1.0;
  try {
    PistonSolid solid(bad);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'mass'"), std::string::npos) << e.what();
  }
  AcousticColumnFluid column(AcousticColumnParameters{});
  EXPECT_THROW(column.advance(2.0 * column.cell_size() / 10.0, Eigen::Vector2d::Zero()), std::invalid_argument);  // CFL 2
}

}  // namespace
}  // namespace valvefsi::coupling::model
