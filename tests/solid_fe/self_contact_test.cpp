// Self-contact within a leaflet (docs/solid_fe.md, "Self-contact"): a 2D strip bent into a U and
// pressed shut folds through itself without the option and stays a thickness apart with it; a
// strip or plate that only bends feels no self-contact (bit-identical runs with and without);
// the penalty's work is in the energy ledger and equals the energy it stores once settled.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <gtest/gtest.h>

#include "test_meshes.hpp"
#include "valvefsi/solid/neo_hookean.hpp"
#include "valvefsi/solid/shell_solver.hpp"

namespace valvefsi::solid::testing {
namespace {

constexpr double kThickness = 0.25e-3, kDepth = 1e-3, kDensity = 1100.0;

std::vector<StripTie> ties_of(const Mesh& mesh) {
  std::vector<StripTie> ties;
  for (std::size_t k = 0; k < mesh.node_sets.at("strip_front").size(); ++k) {
    ties.push_back({mesh.node_sets.at("strip_front")[k], mesh.node_sets.at("strip_back")[k]});
  }
  return ties;
}

// The U: leg A from (L, 0) to (0, 0) (held), a half circle of radius r through (-r, r), leg B from
// (0, 2r) to (L, 2r) (free end). Leg B's triangles carry a pressure pushing it onto leg A (-y).
constexpr double kLeg = 5e-3, kBend = 0.5e-3, kPressure = -500.0;
constexpr int kLegSegments = 10, kBendSegments = 8;

struct FoldRun {
  double lowest_leg_b = 0;    // smallest y of leg B's nodes above leg A (0 <= x <= L) over the run (m)
  double final_leg_b = 0;     // the same at the end (m)
  double penetration_bound = 0;
  // At the step of the largest penalty energy (the first impact): that energy and the contact
  // work the ledger booked since the step before contact began.
  double peak_penalty_energy = 0, contact_work_at_peak = 0;
  double balance_error = 0;
  std::int64_t in_contact = 0;
};

FoldRun press_the_u(bool self_contact, double end_time) {
  std::vector<Eigen::Vector2d> line = straight_polyline({kLeg, 0}, {-1, 0}, kLeg, kLegSegments);
  for (int i = 1; i <= kBendSegments; ++i) {
    const double phi = -0.5 * std::numbers::pi - std::numbers::pi * i / kBendSegments;
    line.emplace_back(kBend * std::cos(phi), kBend + kBend * std::sin(phi));
  }
  const auto leg_b = straight_polyline({0, 2 * kBend}, {1, 0}, kLeg, kLegSegments);
  line.insert(line.end(), leg_b.begin() + 1, leg_b.end());
  const Mesh mesh = strip_mesh({line}, kDepth, kThickness);
  const auto front = static_cast<std::int64_t>(line.size());
  ShellModelOptions options;
  for (std::int64_t i = 0; i <= kLegSegments; ++i) {
    options.fixed_nodes.push_back(i);
    options.fixed_nodes.push_back(front + i);
  }
  std::vector<std::int64_t> leg_b_nodes, loaded;
  for (std::int64_t i = kLegSegments + kBendSegments; i < front; ++i) leg_b_nodes.push_back(i);
  for (std::int64_t s = kLegSegments + kBendSegments; s + 1 < front; ++s) {
    loaded.push_back(2 * s);
    loaded.push_back(2 * s + 1);
  }
  SolverOptions solver_options;
  solver_options.mass_damping_per_s = 300.0;  // settles the pressed leg within the run
  ShellSolver solver(build_shell_model(mesh, options), NeoHookean(1e5), solver_options);
  solver.set_strip_ties(ties_of(mesh));
  // One leaflet: without self-contact its node-triangle pairs are all skipped.
  solver.enable_leaflet_contact(std::vector<int>(static_cast<std::size_t>(mesh.num_nodes()), 0), self_contact);
  solver.set_pressure([](double) { return kPressure; }, loaded);
  FoldRun r;
  r.lowest_leg_b = HUGE_VAL;
  const double factor = solver.options().contact_stiffness_factor;
  solver.set_step_observer([&](const SolverState& s) {
    const double e = solver.leaflet_contact()->penalty_energy(solver.model(), s.position, factor * s.contact_omega2,
                                                              s.contact_candidates);
    if (e > r.peak_penalty_energy) {
      r.peak_penalty_energy = e;
      r.contact_work_at_peak = s.energy.contact_work;
    }
  });
  const auto leg_b_height = [&] {
    double lowest = HUGE_VAL;
    for (const auto i : leg_b_nodes) {
      const Eigen::Vector3d p = solver.state().position.col(i);
      if (p.x() >= 0.0 && p.x() <= kLeg) lowest = std::min(lowest, p.y());
    }
    return lowest;
  };
  for (int k = 1; k * 1e-4 <= end_time + 1e-12; ++k) {
    solver.advance_window(k * 1e-4);
    r.lowest_leg_b = std::min(r.lowest_leg_b, leg_b_height());
  }
  const SolverState& s = solver.state();
  r.final_leg_b = leg_b_height();
  // Static penetration bound: the whole load on leg B, |p| L depth, on the penalty of its lightest
  // node, factor m omega^2 (a lever pressed at its tip carries about half its load there).
  double lightest = HUGE_VAL;
  for (const auto i : leg_b_nodes) lightest = std::min(lightest, solver.elements().nodal_mass()(i));
  r.penetration_bound = std::abs(kPressure) * kLeg * kDepth / (factor * 2.0 * lightest * s.contact_omega2);
  r.balance_error = s.energy.relative_balance_error();
  r.in_contact = s.nodes_in_contact;
  std::printf("U pressed shut, self-contact %s, to %.3g s: leg B lowest %.4g mm over the run, %.4g mm at the end "
              "(t = %.3g mm, penetration bound %.3g mm); %lld pairs in contact; largest penalty energy %.4g J, contact "
              "work then %.4g J (at the end %.4g J); balance error %.2e; %lld steps, %zu candidate pairs\n",
              self_contact ? "on" : "off", end_time, 1e3 * r.lowest_leg_b, 1e3 * r.final_leg_b, 1e3 * kThickness,
              1e3 * r.penetration_bound, static_cast<long long>(r.in_contact), r.peak_penalty_energy,
              r.contact_work_at_peak, s.energy.contact_work, r.balance_error, static_cast<long long>(s.step),
              s.contact_candidates.pairs.size());
  return r;
}

TEST(SelfContact, AStripPressedIntoAUFoldsThroughItselfWithoutTheOption) {
  const FoldRun r = press_the_u(false, 2e-3);
  EXPECT_LT(r.lowest_leg_b, -kThickness) << "leg B should have passed through leg A";
  EXPECT_EQ(r.peak_penalty_energy, 0.0);
}

TEST(SelfContact, WithTheOptionTheFoldStaysAThicknessApartAndTheLedgerHoldsTheContact) {
  const FoldRun r = press_the_u(true, 0.03);
  EXPECT_GT(r.lowest_leg_b, 0.0) << "no crossing at any output time";
  EXPECT_GE(r.final_leg_b, kThickness - r.penetration_bound) << "gap >= t - penetration bound";
  EXPECT_LT(r.final_leg_b, 1.02 * kThickness) << "leg B lies on leg A";
  EXPECT_GT(r.in_contact, 0);
  // The ledger books the penalty's work: at the impact's deepest step it holds the energy the
  // springs store then, up to the trapezoidal booking of a spring switched on between two steps.
  EXPECT_GT(r.peak_penalty_energy, 0.0);
  EXPECT_NEAR(r.contact_work_at_peak, r.peak_penalty_energy, 0.15 * r.peak_penalty_energy);  // measured 9 %
  EXPECT_LT(r.balance_error, 1e-2);
}

// Positions of a strip (2D) or plate (3D) bent by a pressure, with leaflet contact on a single
// leaflet, with and without self-contact; returns the largest difference and the candidate pairs.
struct BendRun {
  Eigen::Matrix3Xd position;
  std::size_t candidates = 0;
  double tip_deflection = 0;
};

BendRun bend_strip(bool self_contact) {
  const Mesh mesh = strip_mesh({straight_polyline({0, 0}, {1, 0}, 0.01, 40)}, kDepth, kThickness);
  ShellModelOptions options;
  options.fixed_nodes = mesh.node_sets.at("attachment");
  SolverOptions solver_options;
  solver_options.mass_damping_per_s = 200.0;
  ShellSolver solver(build_shell_model(mesh, options), NeoHookean(1e5), solver_options);
  solver.set_strip_ties(ties_of(mesh));
  solver.enable_leaflet_contact(std::vector<int>(static_cast<std::size_t>(mesh.num_nodes()), 0), self_contact);
  solver.set_pressure([](double) { return 20.0; });
  for (int k = 1; k <= 200; ++k) solver.advance_window(k * 1e-4);
  const auto tip = mesh.node_sets.at("free_edge")[0];
  return {solver.state().position, solver.state().contact_candidates.pairs.size(),
          solver.state().position(1, tip)};
}

TEST(SelfContact, ABentStripFeelsNoSelfContact) {
  const BendRun off = bend_strip(false), on = bend_strip(true);
  std::printf("bent strip: tip deflection %.4g mm (length 10 mm), %zu self-contact candidate pairs, largest "
              "difference %.3g m\n", 1e3 * on.tip_deflection, on.candidates, (on.position - off.position).cwiseAbs().maxCoeff());
  EXPECT_GT(on.tip_deflection, 3e-3) << "the strip must bend (curvature radius of a few mm)";
  EXPECT_GT(on.candidates, 0U) << "self-contact candidates exist, yet exert nothing";
  EXPECT_EQ(off.candidates, 0U);
  EXPECT_EQ((on.position - off.position).cwiseAbs().maxCoeff(), 0.0);
}

BendRun bend_plate(bool self_contact) {
  const double a = 0.01;
  const Mesh mesh = rectangular_plate(a, a, 12, 12, kThickness);
  ShellModelOptions options;
  options.fixed_nodes = mesh.node_sets.at("left");
  SolverOptions solver_options;
  solver_options.mass_damping_per_s = 300.0;
  ShellSolver solver(build_shell_model(mesh, options), NeoHookean(1e5), solver_options);
  solver.enable_leaflet_contact(std::vector<int>(static_cast<std::size_t>(mesh.num_nodes()), 0), self_contact);
  solver.set_pressure([](double) { return 15.0; });
  for (int k = 1; k <= 150; ++k) solver.advance_window(k * 1e-4);
  const auto corner = grid_node(12, 12, 12);
  return {solver.state().position, solver.state().contact_candidates.pairs.size(), solver.displacement()(2, corner)};
}

TEST(SelfContact, ABentPlateFeelsNoSelfContact) {
  const BendRun off = bend_plate(false), on = bend_plate(true);
  std::printf("bent plate: corner deflection %.4g mm (side 10 mm), %zu self-contact candidate pairs, largest "
              "difference %.3g m\n", 1e3 * on.tip_deflection, on.candidates, (on.position - off.position).cwiseAbs().maxCoeff());
  EXPECT_GT(std::abs(on.tip_deflection), 2e-3);
  EXPECT_GT(on.candidates, 0U);
  EXPECT_EQ((on.position - off.position).cwiseAbs().maxCoeff(), 0.0);
}

}  // namespace
}  // namespace valvefsi::solid::testing
