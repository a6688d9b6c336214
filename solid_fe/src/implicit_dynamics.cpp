// Implicit dynamics of ExplicitSolver (solid.time_integration: IMPLICIT; docs/solid_fe.md,
// "Implicit dynamics"): generalized-alpha (Chung & Hulbert 1993, forces interpolated between the
// step's ends) with Newton-Raphson on the step's residual, an Eigen SparseLU solve (follower
// pressure and penalty contact make the tangent non-symmetric) and an adaptive step that grows
// when Newton converges fast and is cut and retried when it does not. Same fixed nodes, mirror
// planes, contact and follower pressure as the explicit path, which it replaces step for step.
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <fmt/format.h>

#include "valvefsi/solid/energy_growth_error.hpp"
#include "valvefsi/solid/explicit_solver.hpp"
#include "valvefsi/solid/generalized_alpha.hpp"
#include "valvefsi/solid/material_error.hpp"
#include "valvefsi/solid/newton_failure_error.hpp"

namespace valvefsi::solid {

struct ExplicitSolver::ImplicitWork {
  std::vector<Eigen::Matrix3d> projector;  // per node: the constraints as a 3x3 projector (0: fixed)
  std::vector<std::uint8_t> constrained;   // per node: projector is not the identity
  std::vector<NodeBlock> blocks;
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::SparseMatrix<double> matrix;
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> lu;
  // Pattern of the last analysis: constant but for the leaflet-leaflet contact pairs' blocks.
  std::vector<int> analysed_outer, analysed_inner;
  // Modified Newton: the factorised tangent is kept across iterations and steps while the step
  // size is the one it was built for and the residual falls fast enough with it.
  bool factor_valid = false;
  double factor_step = 0;
  double factor_damping = 0;  // the mass damping the kept tangent was built with (it changes in diastole)
  int fast_steps = 0;  // consecutive steps converged within newton_fast_iterations
  // Cost rule: work since the last accepted step (failed tries included) in explicit-step
  // equivalents; moved into SolverState::block_work when a step is accepted.
  double pending_work = 0;
  Eigen::Matrix3Xd dx, a, v, r, net, net_n;
  Eigen::Matrix3Xd imbalance_start, imbalance_end;  // M a + c M v - F at the step's ends (the ledger)
  // The external force before this window's load replaced it, and whether the window's first
  // step is still to come (the ledger's load-step part).
  Eigen::Matrix3Xd external_before_window;
  bool window_first_step = false;
  Eigen::VectorXd delta;
  // The plane and stent springs the factorised tangent holds (one per node: in contact when it was
  // built, and the spring's direction), and the present iterate's. A kept tangent whose set differs
  // is given the iterate's springs by a low-rank (Woodbury) update of its solves instead of a new
  // factorisation (docs/solid_fe.md, "Twentieth session").
  std::vector<std::uint8_t> tangent_in_contact, iterate_in_contact;
  Eigen::Matrix3Xd tangent_direction, iterate_direction;
  struct SpringColumn {
    std::int32_t node = 0;
    bool add = true;              // + the iterate's spring the tangent lacks, - the tangent's the iterate lacks
    Eigen::Vector3d u;            // the spring's direction, projected by the node's constraints
    Eigen::VectorXd solved;       // the kept tangent's solve of the spring's column
  };
  std::vector<SpringColumn> spring_columns;  // the update's columns; valid for the present factorisation
  Eigen::MatrixXd capacitance;
  Eigen::PartialPivLU<Eigen::MatrixXd> capacitance_lu;
};

namespace {
// Above this many changed springs a new factorisation is cheaper than the update's solves (one
// solve per spring; the fine sector's factorisation costs ~70 solves).
constexpr int kMaxSpringUpdate = 64;

// Whether a Newton iteration converging at the observed rate (residual / previous) would need more
// than `fast` iterations in all to reach `tolerance` (the step would then not grow).
bool too_slow_to_grow(int iteration, double residual, double previous, double tolerance, int fast) {
  const double rate = residual / previous;
  if (!(rate < 1.0)) return true;
  return iteration + std::log(tolerance / residual) / std::log(rate) > fast;
}
}  // namespace

void ExplicitSolver::prepare_implicit() {
  if (planar_ || tie_) {
    throw std::invalid_argument(
        "solid: time_integration IMPLICIT is not available with 2D strips or a coaptation tie (allowed: EXPLICIT)");
  }
  const double rho = options_.spectral_radius_infinity;
  if (!(rho >= 0.0 && rho <= 1.0)) {
    throw std::invalid_argument(fmt::format("solid: spectral_radius_infinity = {}: allowed [0, 1]", rho));
  }
  implicit_ = std::make_shared<ImplicitWork>();
  const Eigen::Index n = elements_->reference_positions().cols();
  implicit_->projector.assign(static_cast<std::size_t>(n), Eigen::Matrix3d::Identity());
  implicit_->constrained.assign(static_cast<std::size_t>(n), 0);
  // The constraints are linear per node (no strip ties here): their projector is their action on
  // the three unit vectors.
  Eigen::Matrix3Xd unit(3, n);
  for (int d = 0; d < 3; ++d) {
    unit.setZero();
    unit.row(d).setOnes();
    apply_constraints(unit);
    for (Eigen::Index i = 0; i < n; ++i) implicit_->projector[static_cast<std::size_t>(i)].col(d) = unit.col(i);
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    implicit_->constrained[k] = !implicit_->projector[k].isIdentity(0.0);
  }
}

bool ExplicitSolver::implicit_step(double h, const Eigen::Matrix3Xd* nodal_forces, double& residual,
                                   Eigen::Index& worst_node) {
  ImplicitWork& w = *implicit_;
  const GeneralizedAlphaParameters p = generalized_alpha_parameters(options_.spectral_radius_infinity);
  const Eigen::ArrayXd mass = elements_->nodal_mass().array();
  const double damping = mass_damping_at(state_.time);  // the step's, read at its start
  const SolverState start = state_;  // restored when Newton fails
  const Eigen::Matrix3Xd& x_n = start.position;
  const Eigen::Matrix3Xd& v_n = start.velocity;
  const Eigen::Matrix3Xd& a_n = start.acceleration;
  w.net_n = start.external_force + start.contact_force - start.internal_force;
  const double t_new = state_.time + h;
  const Eigen::Index n = x_n.cols();

  // Predictor: the same acceleration as now. The unknown is the increment dx, not x: at small
  // steps x - x_n would lose the acceleration to round-off (1e-16 x 2 cm / h^2).
  w.dx = h * v_n + 0.5 * h * h * a_n;
  const double mass_coefficient = (1.0 - p.alpha_m) / (p.beta * h * h) + damping * (1.0 - p.alpha_f) * p.gamma / (p.beta * h);
  const double stiffness_coefficient = 1.0 - p.alpha_f;
  residual = std::numeric_limits<double>::infinity();
  worst_node = -1;
  const auto fail = [&] {
    state_ = start;
    internal_force_current_ = true;
    return false;
  };
  // Converged also when the last correction was at round-off of the positions (1e-12 of the
  // model's size): near rest every force is itself round-off and the relative residual stalls.
  const Eigen::Matrix3Xd& reference = elements_->reference_positions();
  const double round_off = 1e-12 * (reference.rowwise().maxCoeff() - reference.rowwise().minCoeff()).norm();
  double correction = std::numeric_limits<double>::infinity();
  double previous_residual = std::numeric_limits<double>::infinity();
  bool built_this_step = false;
  for (int iteration = 0;; ++iteration) {
    state_.position = x_n + w.dx;
    state_.time = t_new;
    w.a = (w.dx - h * v_n - h * h * (0.5 - p.beta) * a_n) / (p.beta * h * h);
    w.v = v_n + h * ((1.0 - p.gamma) * a_n + p.gamma * w.a);
    if (options_.contact_damping_ratio > 0.0) state_.half_step_velocity = w.v;  // the contact dashpots' velocity
    w.pending_work += 1.0;  // one force evaluation, as an explicit step
    try {
      compute_internal_force(false);
      compute_contact_force();
      compute_external_force(t_new, nodal_forces);
    } catch (const MaterialStateError&) {
      return fail();  // a trial state the material cannot take: a smaller step will not go there
    }
    w.net = state_.external_force + state_.contact_force - state_.internal_force;
    // Inertia (and mass damping) at n+1-alpha_m (n+1-alpha_f) against the forces at n+1-alpha_f.
    w.r = ((1.0 - p.alpha_m) * w.a + p.alpha_m * a_n + damping * ((1.0 - p.alpha_f) * w.v + p.alpha_f * v_n))
              .array()
              .rowwise() *
          mass.transpose();
    w.r -= (1.0 - p.alpha_f) * w.net + p.alpha_f * w.net_n;
    apply_constraints(w.r);
    const double scale = std::max({(w.a.array().rowwise() * mass.transpose()).matrix().norm(),
                                   state_.internal_force.norm(), state_.external_force.norm(),
                                   state_.contact_force.norm(), w.net_n.norm(), 1e-300});
    residual = w.r.norm() / scale;
    if (!std::isfinite(residual)) return fail();
    w.r.colwise().norm().maxCoeff(&worst_node);
    if (residual <= options_.newton_tolerance || correction <= round_off) {
      state_.newton_iterations = iteration;
      break;
    }
    if (iteration >= options_.newton_max_iterations) {
      w.factor_valid = false;  // the retry starts from a fresh tangent
      return fail();
    }
    const bool set_changed = update_iterate_contact_set(iteration == 0);
    // A kept tangent is refreshed when it was built for another step size or damping; when the
    // residual fell by less than 4x in the last iteration with it, unless the plane and stent
    // contact set changed in that iteration (the spring update below covers the contact; a flip
    // costs an iteration, not the tangent); and once per step when a tangent kept from an earlier
    // step converges too slowly for the step to grow. (Measured on the fine sector: a kept tangent
    // whose contact set had gone stale converged linearly at 0.15-0.19 per iteration, below the 4x
    // test, so it was never rebuilt and every step took 6 iterations: the step neither grew nor
    // shrank; docs/solid_fe.md, "Twentieth session".)
    const bool slow = iteration > 0 && residual > 0.25 * previous_residual && !set_changed;
    const bool stale = iteration > 0 && !built_this_step && !set_changed &&
                       too_slow_to_grow(iteration, residual, previous_residual, options_.newton_tolerance,
                                        options_.newton_fast_iterations);
    const bool refresh = !w.factor_valid || std::abs(w.factor_step - h) > 1e-9 * h || w.factor_damping != damping ||
                         slow || stale;
    previous_residual = residual;
    if (refresh || !prepare_spring_update(stiffness_coefficient)) {
      if (!factorise_tangent(h, t_new, mass_coefficient, stiffness_coefficient)) return fail();
      w.factor_damping = damping;
      built_this_step = true;
    }
    w.delta = w.lu.solve(-Eigen::Map<const Eigen::VectorXd>(w.r.data(), 3 * n));
    if (w.lu.info() != Eigen::Success || !w.delta.allFinite() || !apply_spring_update(w.delta)) {
      w.factor_valid = false;
      return fail();
    }
    w.r = Eigen::Map<const Eigen::Matrix3Xd>(w.delta.data(), 3, n);
    apply_constraints(w.r);
    w.dx += w.r;
    correction = w.r.cwiseAbs().maxCoeff();
  }
  return finish_implicit_step(start, h);
}

bool ExplicitSolver::factorise_tangent(double h, double t_new, double mass_coefficient, double stiffness_coefficient) {
  ImplicitWork& w = *implicit_;
  const Eigen::ArrayXd mass = elements_->nodal_mass().array();
  const Eigen::Index n = state_.position.cols();
  w.factor_valid = false;
  w.pending_work += options_.implicit_tangent_cost;
  {
    // Tangent: mass_coefficient M + (1 - alpha_f) (K_int - K_pressure + K_contact), constrained
    // rows and columns projected, their diagonal kept at the mass term so the matrix stays regular.
    try {
      elements_->internal_force_tangent(state_.position, w.blocks);
    } catch (const MaterialStateError&) {
      return false;
    }
    const std::size_t internal_blocks = w.blocks.size();
    if (pressure_) elements_->add_pressure_tangent(state_.position, pressure_(t_new), w.blocks);
    w.triplets.clear();
    w.triplets.reserve(9 * (w.blocks.size() + static_cast<std::size_t>(n)));
    const auto add_block = [&](std::int32_t row, std::int32_t col, const Eigen::Matrix3d& k) {
      Eigen::Matrix3d b = k;
      if (w.constrained[static_cast<std::size_t>(row)]) b = w.projector[static_cast<std::size_t>(row)] * b;
      if (w.constrained[static_cast<std::size_t>(col)]) b = b * w.projector[static_cast<std::size_t>(col)];
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) w.triplets.emplace_back(3 * row + i, 3 * col + j, b(i, j));
      }
    };
    for (std::size_t k = 0; k < w.blocks.size(); ++k) {
      const double sign = k < internal_blocks ? stiffness_coefficient : -stiffness_coefficient;
      add_block(w.blocks[k].row, w.blocks[k].col, sign * w.blocks[k].k);
    }
    // Penalty contact on planes and the stent: k n n^T along the node's own spring (exact for one
    // per node). Leaflet-leaflet pairs: their full tangent, which couples the node to the opposite
    // triangle's nodes (with only the node's own part Newton needed 4-6 iterations and cut the
    // full valve's steps to a few us; docs/solid_fe.md, "Thirteenth session").
    const double penalty = options_.contact_stiffness_factor * state_.contact_omega2;
    const Eigen::Matrix3Xd& own = leaflet_contact_ ? own_contact_force_ : state_.contact_force;
    w.tangent_in_contact.assign(static_cast<std::size_t>(n), 0);
    w.tangent_direction.setZero(3, n);
    w.spring_columns.clear();
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto node = static_cast<std::int32_t>(i);
      const double f = own.col(i).norm();
      if (f > 0.0) {
        const Eigen::Vector3d u = own.col(i) / f;
        w.tangent_in_contact[static_cast<std::size_t>(i)] = 1;
        w.tangent_direction.col(i) = u;
        add_block(node, node, (stiffness_coefficient * penalty * mass(i)) * (u * u.transpose()));
      }
      add_block(node, node, Eigen::Matrix3d::Zero());  // keeps the pattern whether in contact or not
      for (int d = 0; d < 3; ++d) w.triplets.emplace_back(3 * node + d, 3 * node + d, mass_coefficient * mass(i));
    }
    if (leaflet_contact_) {
      w.blocks.clear();
      leaflet_contact_->add_tangent(*elements_->contact_surface(), state_.position, penalty, state_.contact_candidates,
                                    w.blocks);
      for (const auto& b : w.blocks) add_block(b.row, b.col, stiffness_coefficient * b.k);
      if (options_.contact_damping_ratio > 0.0) {
        // The pairs' dashpots through the trial velocity: d(v)/d(x) = gamma / (beta h).
        const GeneralizedAlphaParameters p = generalized_alpha_parameters(options_.spectral_radius_infinity);
        w.blocks.clear();
        leaflet_contact_->add_damping_tangent(*elements_->contact_surface(), state_.position, penalty,
                                              options_.contact_damping_ratio,
                                              stiffness_coefficient * p.gamma / (p.beta * h), state_.contact_candidates,
                                              w.blocks);
        for (const auto& b : w.blocks) add_block(b.row, b.col, b.k);
      }
    }
    w.matrix.resize(3 * n, 3 * n);
    w.matrix.setFromTriplets(w.triplets.begin(), w.triplets.end());
    const auto outer = std::span(w.matrix.outerIndexPtr(), static_cast<std::size_t>(w.matrix.outerSize() + 1));
    const auto inner = std::span(w.matrix.innerIndexPtr(), static_cast<std::size_t>(w.matrix.nonZeros()));
    if (!std::ranges::equal(outer, w.analysed_outer) || !std::ranges::equal(inner, w.analysed_inner)) {
      w.lu.analyzePattern(w.matrix);
      w.analysed_outer.assign(outer.begin(), outer.end());
      w.analysed_inner.assign(inner.begin(), inner.end());
    }
    w.lu.factorize(w.matrix);
    if (w.lu.info() != Eigen::Success) return false;
  }
  w.factor_valid = true;
  w.factor_step = h;
  return true;
}

bool ExplicitSolver::update_iterate_contact_set(bool first_iterate) {
  ImplicitWork& w = *implicit_;
  const Eigen::Index n = state_.position.cols();
  const Eigen::Matrix3Xd& own = leaflet_contact_ ? own_contact_force_ : state_.contact_force;
  bool changed = false;
  if (first_iterate || w.iterate_in_contact.size() != static_cast<std::size_t>(n)) {
    w.iterate_in_contact.assign(static_cast<std::size_t>(n), 0);
    w.iterate_direction.setZero(3, n);
    first_iterate = true;
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double f = own.col(i).norm();
    const std::uint8_t in = f > 0.0 ? 1 : 0;
    changed = changed || in != w.iterate_in_contact[k];
    w.iterate_in_contact[k] = in;
    if (in) w.iterate_direction.col(i) = own.col(i) / f;
  }
  return changed && !first_iterate;
}

bool ExplicitSolver::prepare_spring_update(double stiffness_coefficient) {
  ImplicitWork& w = *implicit_;
  const Eigen::Index n = state_.position.cols();
  const Eigen::VectorXd& mass = elements_->nodal_mass();
  const double penalty = options_.contact_stiffness_factor * state_.contact_omega2;
  if (w.tangent_in_contact.size() != static_cast<std::size_t>(n)) return false;
  // The springs the iterate has and the tangent lacks (+), and the reverse (-): exactly the
  // difference of the two contact parts, k u u^T per node, projected like the tangent's blocks.
  std::vector<ImplicitWork::SpringColumn> columns;
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const bool now = w.iterate_in_contact[k] != 0;
    if (now == (w.tangent_in_contact[k] != 0)) continue;
    if (static_cast<int>(columns.size()) >= kMaxSpringUpdate) return false;
    ImplicitWork::SpringColumn c;
    c.node = static_cast<std::int32_t>(i);
    c.add = now;
    c.u = now ? Eigen::Vector3d(w.iterate_direction.col(i)) : Eigen::Vector3d(w.tangent_direction.col(i));
    if (w.constrained[k]) c.u = w.projector[k] * c.u;
    const auto cached = std::ranges::find_if(w.spring_columns, [&](const ImplicitWork::SpringColumn& s) {
      return s.node == c.node && s.add == c.add && s.u == c.u;
    });
    if (cached != w.spring_columns.end()) {
      c.solved = std::move(cached->solved);
    } else {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(3 * n);
      e.segment<3>(3 * i) = c.u;
      c.solved = w.lu.solve(e);
      if (w.lu.info() != Eigen::Success || !c.solved.allFinite()) return false;
      w.pending_work += 1.0;  // a solve: about a force evaluation
    }
    columns.push_back(std::move(c));
  }
  w.spring_columns = std::move(columns);
  // (K + U C U^T)^-1 = K^-1 - K^-1 U (C^-1 + U^T K^-1 U)^-1 U^T K^-1, C = diag(+-(1 - alpha_f) k_i).
  const auto r = static_cast<Eigen::Index>(w.spring_columns.size());
  if (r == 0) return true;
  w.capacitance.resize(r, r);
  for (Eigen::Index a = 0; a < r; ++a) {
    const ImplicitWork::SpringColumn& ca = w.spring_columns[static_cast<std::size_t>(a)];
    for (Eigen::Index b = 0; b < r; ++b) {
      w.capacitance(a, b) = ca.u.dot(w.spring_columns[static_cast<std::size_t>(b)].solved.segment<3>(3 * ca.node));
    }
    const double spring = stiffness_coefficient * penalty * mass(ca.node);
    w.capacitance(a, a) += ca.add ? 1.0 / spring : -1.0 / spring;
  }
  w.capacitance_lu.compute(w.capacitance);
  return w.capacitance_lu.rcond() > 1e-12;
}

bool ExplicitSolver::apply_spring_update(Eigen::VectorXd& solved) const {
  const ImplicitWork& w = *implicit_;
  const auto r = static_cast<Eigen::Index>(w.spring_columns.size());
  if (r == 0) return true;
  Eigen::VectorXd projected(r);
  for (Eigen::Index a = 0; a < r; ++a) {
    const ImplicitWork::SpringColumn& c = w.spring_columns[static_cast<std::size_t>(a)];
    projected(a) = c.u.dot(solved.segment<3>(3 * c.node));
  }
  const Eigen::VectorXd z = w.capacitance_lu.solve(projected);
  for (Eigen::Index a = 0; a < r; ++a) solved -= z(a) * w.spring_columns[static_cast<std::size_t>(a)].solved;
  return solved.allFinite();
}

bool ExplicitSolver::finish_implicit_step(const SolverState& start, double h) {
  ImplicitWork& w = *implicit_;
  const Eigen::ArrayXd mass = elements_->nodal_mass().array();
  const double damping = mass_damping_at(start.time);  // as implicit_step's
  const Eigen::Matrix3Xd& v_n = start.velocity;
  const Eigen::Index n = v_n.cols();

  // Converged: the state at t_new, and the step's booking: trapezoidal works as the explicit
  // ledger, and the scheme's own dissipation from its energy identity (generalized_alpha.hpp), so
  // that the balance is the work of the converged residual, sum dx . r (Newton tolerance).
  state_.velocity = w.v;
  state_.half_step_velocity = w.v;
  state_.acceleration = w.a;
  ++state_.step;
  state_.last_step = h;
  const Eigen::Matrix3Xd& dx = w.dx;
  EnergyBalance& e = state_.energy;
  const double internal = 0.5 * (start.internal_force + state_.internal_force).cwiseProduct(dx).sum();
  const double external = 0.5 * (start.external_force + state_.external_force).cwiseProduct(dx).sum();
  const double contact = -0.5 * (start.contact_force + state_.contact_force).cwiseProduct(dx).sum();
  double damped = 0.0;
  if (damping > 0.0) {
    for (Eigen::Index i = 0; i < n; ++i) damped += damping * mass(i) * 0.5 * (v_n.col(i) + w.v.col(i)).dot(dx.col(i));
  }
  e.internal_work += internal;
  e.external_work += external;
  e.contact_work += contact;
  e.damping_work += damped;
  update_kinetic_energy();
  const auto imbalance = [&](const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& v, const Eigen::Matrix3Xd& net,
                             Eigen::Matrix3Xd& out) { out = ((a + damping * v).array().rowwise() * mass.transpose()).matrix() - net; };
  imbalance(start.acceleration, v_n, w.net_n, w.imbalance_start);
  imbalance(w.a, w.v, w.net, w.imbalance_end);
  const GeneralizedAlphaParameters p = generalized_alpha_parameters(options_.spectral_radius_infinity);
  e.numerical_dissipation += generalized_alpha_dissipation(p, h, elements_->nodal_mass(), dx, start.acceleration,
                                                           w.a, w.imbalance_start, w.imbalance_end);
  if (w.window_first_step) {
    e.load_step_dissipation +=
        (0.5 - p.alpha_f) * dx.cwiseProduct(start.external_force - w.external_before_window).sum();
    w.window_first_step = false;
  }
  return true;
}

bool ExplicitSolver::implicit_costs_more() {
  ImplicitWork& w = *implicit_;
  state_.block_work += w.pending_work;
  w.pending_work = 0.0;
  if (++state_.phase_steps % kCostRuleSteps != 0) return false;
  // The block's work against the explicit steps its time would have taken; the first block is
  // the step's ramp from implicit_initial_step, paid once per phase, and is not judged. A block
  // whose step grew is not judged either: the scheme is still damping what the explicit phase
  // left (the closed sector rings at 6-25 us steps for ~10 ms, then takes 0.1 ms steps; going
  // back to explicit there keeps the ringing and the next try starts over).
  const double explicit_steps =
      state_.explicit_step_at_switch > 0.0 ? (state_.time - state_.block_start) / state_.explicit_step_at_switch : 0.0;
  const bool costs_more = state_.phase_steps > kCostRuleSteps && state_.explicit_step_at_switch > 0.0 &&
                          state_.implicit_step <= state_.block_start_step && state_.block_work > explicit_steps;
  state_.block_work = 0.0;
  state_.block_start = state_.time;
  state_.block_start_step = state_.implicit_step;
  return costs_more;
}

void ExplicitSolver::start_cost_rule() {
  state_.explicit_step_at_switch = state_.uncut_step;
  state_.phase_steps = 0;
  state_.block_work = 0.0;
  state_.block_start = state_.time;
  state_.block_start_step = 0.0;
  if (implicit_) implicit_->pending_work = 0.0;
}

void ExplicitSolver::drop_kept_tangent() {
  if (!implicit_) return;
  implicit_->factor_valid = false;
  implicit_->fast_steps = 0;
}

void ExplicitSolver::advance_window_implicit(double t_end, const Eigen::Matrix3Xd* nodal_forces) {
  if (!implicit_) prepare_implicit();
  const Eigen::Index n = state_.position.cols();
  implicit_->external_before_window = state_.external_force;
  compute_external_force(state_.time, nodal_forces);  // this window's load at its start
  if (state_.acceleration.cols() != n) {
    // Start (or the switch from explicit): the acceleration the equation of motion gives now.
    compute_acceleration(elements_->nodal_mass().array().inverse());
    state_.acceleration = acceleration_ - mass_damping_at(state_.time) * state_.velocity;
    apply_constraints(state_.acceleration);
    implicit_->external_before_window = state_.external_force;  // that acceleration holds the new load
  }
  implicit_->window_first_step = implicit_->external_before_window.cols() == n;
  // Steps are max_time_step / 2^k, so that they divide output windows of that size and a kept
  // tangent (built for one step size) serves many steps.
  double h = options_.max_time_step;
  const double first = state_.implicit_step > 0.0 ? state_.implicit_step : options_.implicit_initial_step;
  while (h > first * (1.0 + 1e-9)) h *= 0.5;
  while (state_.time < t_end) {
    h = std::min(h, options_.max_time_step);
    if (automatic() && pressure_) {
      const double p = pressure_(state_.time);
      const double allowed = kAutomaticLoadChangePerStep * std::max(std::abs(p), std::abs(state_.implicit_switch_pressure));
      while (h > options_.implicit_min_step && std::abs(pressure_(state_.time + h) - p) > allowed) h *= 0.5;
    }
    const double remaining = t_end - state_.time;
    double step = h;
    bool lands = false;
    if (remaining <= h * (1.0 + 1e-9)) {
      step = remaining;
      lands = true;
    } else if (remaining < 2.0 * h) {
      step = 0.5 * remaining;  // no sliver step before the window's end
    }
    double residual = 0.0;
    Eigen::Index worst = -1;
    if (implicit_step(step, nodal_forces, residual, worst)) {
      if (lands) state_.time = t_end;
      // Grow after fast convergence, shrink after slow; a step cut to land on the window's end
      // does not set the next one.
      ImplicitWork& w = *implicit_;
      if (state_.newton_iterations <= options_.newton_fast_iterations) {
        // Doubling rebuilds the tangent: only after a run of fast steps.
        if (!lands && ++w.fast_steps >= 2) {
          h *= 2.0;
          w.fast_steps = 0;
        }
      } else {
        w.fast_steps = 0;
        if (state_.newton_iterations >= options_.newton_max_iterations - 2) h *= 0.5;
      }
      state_.implicit_step = h;
      state_.stable_step = h;
      state_.critical_element = -1;
      state_.step_calibration = 1.0;
      state_.energy.update_largest_energy();
      if (step_observer_) step_observer_(state_);
      if (options_.max_energy_balance_error > 0.0 && state_.step >= kEnergyCheckFirstStep) check_energy_growth();
      if (automatic()) update_slow_velocity(step);
      if (automatic() && moving_again()) {
        switch_to_explicit();
        return;
      }
      if (automatic() && options_.implicit_tangent_cost > 0.0 && implicit_costs_more()) {
        ++state_.cost_switches;
        switch_to_explicit();
        return;
      }
      continue;
    }
    implicit_->fast_steps = 0;
    h = 0.25 * h;
    if (h < options_.implicit_min_step) {
      const Eigen::Vector3d xw = worst >= 0 ? Eigen::Vector3d(state_.position.col(worst)) : Eigen::Vector3d::Zero();
      throw NewtonFailureError(fmt::format(
          "solid: implicit step failed at t = {:.9g} s, step {}: Newton did not converge within {} iterations even "
          "at dt = {:.3g} s (cut below solid.implicit_min_step_s = {:.3g} s); last relative residual {:.3g} "
          "(tolerance {:.3g}), largest at node {} (at [{:.4g}, {:.4g}, {:.4g}] m). Raise "
          "solid.newton_max_iterations, lower solid.implicit_min_step_s, or use time_integration: EXPLICIT.",
          state_.time, state_.step, options_.newton_max_iterations, step, options_.implicit_min_step, residual,
          options_.newton_tolerance, worst, xw.x(), xw.y(), xw.z()));
    }
  }
}

}  // namespace valvefsi::solid
