// Diagnostic for issue 3's closed full valve (docs/solid_fe.md, "Sixteenth session"): what sets
// the explicit step of a restart state, and what the contact does there. Reads a case and one
// restart point, then prints
//   - the step bookkeeping of the state (element bound, calibration, contact omega^2);
//   - the model's highest frequency by power iteration on M^-1 K with K from the internal forces
//     alone and from internal + contact forces (finite differences), so the contact's share of
//     the stable step is measured, not assumed;
//   - the leaflet pairs in contact: penetration / thickness, and per node the contact stiffness
//     summed over every pair acting on it (node side k, triangle side w_a k) against its mass;
//   - the elements with the smallest step bounds: their largest stretch, in contact or not;
//   - where the kinetic energy sits (nodes in contact, free-edge rows);
// and with --ms > 0 advances that long in --window windows, printing per window the steps, the
// mean step, the critical element, energies, pairs in contact and how often the contact count
// changed between steps, and the CPU time.
//   solid_closed_valve_probe --case C --restart DIR/t_0.300000000 [--ms 2] [--window 0.1]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <numeric>
#include <vector>

#include <CLI/CLI.hpp>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/case/pressure_waveform.hpp"
#include "valvefsi/coupling/restart_file.hpp"
#include "valvefsi/coupling/restart_points.hpp"
#include "valvefsi/solid/case_setup.hpp"
#include "valvefsi/solid/shell_elements.hpp"
#include "valvefsi/solid/shell_forces.hpp"
#include "valvefsi/solid/shell_solver.hpp"
#include "valvefsi/solid/solver_restart.hpp"

namespace {
using namespace valvefsi::solid;

double cpu_seconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

// Largest eigenvalue of M^-1 K by power iteration, K q = -(f(x + h q) - f(x)) / h for the force
// `force(x, out)` (internal minus contact: a stiffness), fixed nodes held.
template <class Force>
double highest_omega2(const ShellSolver& solver, const Force& force, int iterations) {
  const Eigen::Matrix3Xd& x = solver.state().position;
  const auto n = x.cols();
  const Eigen::ArrayXd mass = solver.elements().nodal_mass().array();
  const auto& fixed = solver.elements().fixed();
  Eigen::Matrix3Xd q = Eigen::Matrix3Xd::Random(3, n), f0(3, n), f1(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    if (fixed[static_cast<std::size_t>(i)]) q.col(i).setZero();
  }
  force(x, f0);
  double lambda = 0;
  const double scale = 1e-9;  // m: far below the thickness, far above round-off
  for (int it = 0; it < iterations; ++it) {
    q /= q.cwiseAbs().maxCoeff();
    force(x + scale * q, f1);
    Eigen::Matrix3Xd kq = (f1 - f0) / scale;
    kq.array().rowwise() /= mass.transpose();
    for (Eigen::Index i = 0; i < n; ++i) {
      if (fixed[static_cast<std::size_t>(i)]) kq.col(i).setZero();
    }
    // Rayleigh quotient in the mass inner product.
    const double num = ((q.cwiseProduct(kq)).colwise().sum().transpose().array() * mass).sum();
    const double den = ((q.cwiseProduct(q)).colwise().sum().transpose().array() * mass).sum();
    lambda = num / den;
    q = kq;
  }
  return lambda;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"what sets the explicit step of a closed valve's restart state"};
  std::string case_file, restart;
  double ms = 0, window = 0.1;
  int iterations = 300;
  app.add_option("--case", case_file)->required();
  app.add_option("--restart", restart, "a restart folder (t_<time>) or a restart/ folder (its LATEST)")->required();
  app.add_option("--ms", ms, "advance this many ms after the analysis");
  app.add_option("--window", window, "ms per printed window");
  app.add_option("--iterations", iterations, "power iterations for omega_max");
  std::string work_map;
  app.add_option("--work-map", work_map,
                 "with --ms: write per node x, y, z, pressure work, contact work over the run (csv)");
  CLI11_PARSE(app, argc, argv);

  const auto c = valvefsi::load_case(case_file);
  SolidSetup setup = setup_from_case(c, case_file);
  ShellSolver& solver = setup.shell_solver();
  const valvefsi::PressureWaveform waveform(c.waveform(), case_file);
  solver.set_pressure_waveform([&waveform](double t) { return waveform.transvalvular_pressure(t); });
  solver.advance_window(0.0);
  const auto folder = valvefsi::coupling::resolve_restart_folder(restart, {"solid"});
  read_solver_restart(valvefsi::coupling::restart_file_path(folder, "solid"), solver);

  const ShellModel& model = solver.model();
  const SolverState& s = solver.state();
  const Eigen::Index n = model.reference_positions.cols();
  const double factor = solver.options().contact_stiffness_factor;
  const double k_per_mass = factor * s.contact_omega2;
  std::printf("t = %.6f s, step %lld: stable_step %.4g us (element %lld, calibration x%.2f), last step %.4g us\n",
              s.time, static_cast<long long>(s.step), 1e6 * s.stable_step, static_cast<long long>(s.critical_element),
              s.step_calibration, 1e6 * s.last_step);
  std::printf("  Lanczos at step %lld: 2/omega_max %.4g us (element bound then %.4g us)\n",
              static_cast<long long>(s.calibrated_at_step), 1e6 * s.calibrated_step,
              1e6 * s.element_step_at_calibration);
  std::printf("  contact: omega2 %.4g /s^2 (2/omega %.4g us), factor %.3g: penalty 2/omega_pen = %.4g us; step "
              "divided by sqrt(1 + factor) = %.4f\n",
              s.contact_omega2, 2e6 / std::sqrt(s.contact_omega2), factor, 2e6 / std::sqrt(k_per_mass),
              std::sqrt(1.0 + factor));
  std::printf("  energies: kinetic %.4g J, strain %.4g J, contact work %.4g J, external work %.4g J\n",
              s.energy.kinetic, s.energy.strain_energy, s.energy.contact_work, s.energy.external_work);

  // Contact pairs in contact now, and the per-node contact stiffness over all pairs acting on it.
  const LeafletContact* contact = solver.leaflet_contact();
  Eigen::VectorXd node_k = Eigen::VectorXd::Zero(n);  // Gershgorin row sum of the pair stiffness
  Eigen::VectorXd node_pairs = Eigen::VectorXd::Zero(n);
  std::vector<std::uint8_t> touching(static_cast<std::size_t>(n), 0);
  const Eigen::VectorXd half = solver.elements().contact_half_thickness();
  int in_contact = 0;
  double deepest = 0, deepest_rel = 0;
  std::vector<double> penetration_rel;
  if (contact != nullptr) {
    for (const auto& [i, e] : s.contact_candidates.pairs) {
      const ShellElement& el = model.elements[static_cast<std::size_t>(e)];
      Eigen::Vector3d w;
      const Eigen::Vector3d cp = closest_point_on_triangle(s.position.col(i), s.position.col(el.nodes[0]),
                                                           s.position.col(el.nodes[1]), s.position.col(el.nodes[2]), w);
      const double g = (s.position.col(i) - cp).norm() - (half(i) + 0.5 * el.thickness);
      if (g >= 0) continue;
      ++in_contact;
      const double t = 2.0 * half(i);
      penetration_rel.push_back(-g / t);
      if (-g > deepest) {
        deepest = -g;
        deepest_rel = -g / t;
      }
      const double k = k_per_mass * model.nodal_mass(i);
      // The pair's stiffness k (1, -w)(1, -w)^T along the normal: row sums |.| of node i: k (1 + sum w)
      // = 2k, of triangle node a: w_a k (1 + 1) = 2 w_a k.
      node_k(i) += 2.0 * k;
      node_pairs(i) += 1;
      touching[static_cast<std::size_t>(i)] = 1;
      for (int a = 0; a < 3; ++a) {
        node_k(el.nodes[a]) += 2.0 * w(a) * k;
        node_pairs(el.nodes[a]) += w(a);
        if (w(a) > 0) touching[static_cast<std::size_t>(el.nodes[a])] = 1;
      }
    }
  }
  std::sort(penetration_rel.begin(), penetration_rel.end());
  const auto pct = [&](double p) {
    return penetration_rel.empty() ? 0.0
                                   : penetration_rel[static_cast<std::size_t>(p * static_cast<double>(penetration_rel.size() - 1))];
  };
  std::printf("  leaflet pairs in contact: %d of %zu candidates; penetration / t: median %.3g, 90 %% %.3g, max %.3g "
              "(%.3g um)\n",
              in_contact, s.contact_candidates.pairs.size(), pct(0.5), pct(0.9), deepest_rel, 1e6 * deepest);
  Eigen::Index worst = 0;
  const Eigen::VectorXd omega2_contact = node_k.cwiseQuotient(model.nodal_mass);
  omega2_contact.maxCoeff(&worst);
  std::printf("  per-node contact stiffness (Gershgorin, all pairs on the node): max omega^2 %.4g /s^2 at node %lld "
              "(%.2f pairs' worth): 2/omega = %.4g us; most pairs on one node %.2f\n",
              omega2_contact(worst), static_cast<long long>(worst), node_pairs(worst),
              2e6 / std::sqrt(std::max(omega2_contact(worst), 1e-300)), node_pairs.maxCoeff());

  // Highest frequency with and without the contact stiffness.
  Eigen::Matrix3Xd scratch(3, n);
  ShellElements shell(model, solver.material());
  auto internal = [&](const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& out) {
    shell.internal_force(x, false, out, nullptr);
  };
  ContactCandidates candidates = s.contact_candidates;
  auto with_contact = [&](const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& out) {
    shell.internal_force(x, false, out, nullptr);
    if (contact == nullptr) return;
    scratch.setZero();
    contact->add_forces(model, x, k_per_mass, scratch, candidates);
    out -= scratch;
  };
  const double cpu0 = cpu_seconds();
  const double w2_int = highest_omega2(solver, internal, iterations);
  const double w2_all = highest_omega2(solver, with_contact, iterations);
  std::printf("  power iteration (%d its, %.1f s CPU): 2/omega_max internal %.4g us, internal + contact %.4g us\n",
              iterations, cpu_seconds() - cpu0, 2e6 / std::sqrt(w2_int), 2e6 / std::sqrt(w2_all));

  // Smallest element bounds.
  const auto elements = static_cast<std::int64_t>(model.elements.size());
  std::vector<HingeSide> sides(static_cast<std::size_t>(3 * elements));
  for (std::int64_t e = 0; e < elements; ++e) own_hinge_sides(model, e, s.position, sides.data());
  std::vector<double> bound(static_cast<std::size_t>(elements));
  Eigen::Matrix3Xd forces = Eigen::Matrix3Xd::Zero(3, n);
  Eigen::VectorXd stress, strain;
  solver.element_fields(stress, strain);
  std::visit(
      [&](const auto& law) {
        for (std::int64_t e = 0; e < elements; ++e) {
          bound[static_cast<std::size_t>(e)] =
              add_element_internal_force(model, model.elements[static_cast<std::size_t>(e)], law, s.position, forces,
                                         true, sides.data(), e)
                  .stable_step;
        }
      },
      solver.material());
  std::vector<std::int64_t> order(bound.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](auto a, auto b) { return bound[static_cast<std::size_t>(a)] < bound[static_cast<std::size_t>(b)]; });
  std::printf("  smallest element bounds (no safety): element, bound, max log strain, max stress, membrane log "
              "strain, nodes touching, fixed nodes\n");
  for (int k = 0; k < 10; ++k) {
    const auto e = order[static_cast<std::size_t>(k)];
    const ShellElement& el = model.elements[static_cast<std::size_t>(e)];
    const ElementState st = element_kinematics(model, el, s.position);
    int touch = 0, fixed = 0;
    for (const auto a : el.nodes) {
      touch += touching[static_cast<std::size_t>(a)];
      fixed += model.fixed[static_cast<std::size_t>(a)];
    }
    std::printf("    %5lld %.3g us  %.3f  %.3g MPa  %.3f  %d  %d\n", static_cast<long long>(e),
                1e6 * bound[static_cast<std::size_t>(e)], strain(e), 1e-6 * stress(e),
                0.5 * std::log(max_eigenvalue(st.membrane_c)), touch, fixed);
  }
  std::vector<double> sorted_strain(strain.data(), strain.data() + strain.size());
  std::sort(sorted_strain.begin(), sorted_strain.end());
  std::vector<double> sorted_stress(stress.data(), stress.data() + stress.size());
  std::sort(sorted_stress.begin(), sorted_stress.end());
  const auto q = [](const std::vector<double>& v, double p) {
    return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))];
  };
  std::printf("  element fields: log strain median %.3f, 99 %% %.3f, max %.3f; stress median %.3g, 99 %% %.3g, max "
              "%.3g MPa\n",
              q(sorted_strain, 0.5), q(sorted_strain, 0.99), sorted_strain.back(), 1e-6 * q(sorted_stress, 0.5),
              1e-6 * q(sorted_stress, 0.99), 1e-6 * sorted_stress.back());

  // Kinetic energy: on nodes touching, and the top nodes.
  double ke_touch = 0, ke_all = 0;
  Eigen::VectorXd ke(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    ke(i) = 0.5 * model.nodal_mass(i) * s.velocity.col(i).squaredNorm();
    ke_all += ke(i);
    if (touching[static_cast<std::size_t>(i)]) ke_touch += ke(i);
  }
  const auto touching_count = std::count(touching.begin(), touching.end(), 1);
  std::printf("  kinetic energy: %.3g J, of it %.1f %% on the %lld nodes touching (%.1f %% of the nodes)\n", ke_all,
              100 * ke_touch / ke_all, static_cast<long long>(touching_count),
              100.0 * static_cast<double>(touching_count) / static_cast<double>(n));
  std::fflush(stdout);

  if (ms <= 0) return 0;
  std::int64_t steps = 0, changes = 0, last_count = -1;
  double min_stable = HUGE_VAL;
  // Per node: the pressure's and the contact's work, trapezoidal as the ledger books them.
  Eigen::VectorXd pressure_work = Eigen::VectorXd::Zero(n), contact_work = Eigen::VectorXd::Zero(n);
  Eigen::Matrix3Xd last_x = s.position, last_external = s.external_force, last_contact = s.contact_force;
  solver.set_step_observer([&](const SolverState& st) {
    if (!work_map.empty()) {
      const Eigen::Matrix3Xd dx = st.position - last_x;
      pressure_work += (0.5 * (st.external_force + last_external).cwiseProduct(dx)).colwise().sum().transpose();
      contact_work -= (0.5 * (st.contact_force + last_contact).cwiseProduct(dx)).colwise().sum().transpose();
      last_x = st.position;
      last_external = st.external_force;
      last_contact = st.contact_force;
    }
    ++steps;
    if (last_count >= 0 && st.nodes_in_contact != last_count) ++changes;
    last_count = st.nodes_in_contact;
    min_stable = std::min(min_stable, st.stable_step);
  });
  std::printf("window end (s), steps, mean dt (us), min stable (us), critical element, calibration, kinetic, strain, "
              "contact work (J), in contact, contact-count changes, energy error, CPU (s)\n");
  const double t0 = s.time;
  const int windows = static_cast<int>(std::lround(ms / window));
  double cpu = cpu_seconds();
  for (int w = 1; w <= windows; ++w) {
    steps = changes = 0;
    min_stable = HUGE_VAL;
    const double t_start = solver.state().time;
    solver.advance_window(t0 + w * window * 1e-3);
    const SolverState& st = solver.state();
    const double now = cpu_seconds();
    std::printf("%.5f %lld %.4g %.4g %lld %.2f %.4g %.4g %.4g %lld %lld %.3g %.2f\n", st.time,
                static_cast<long long>(steps), 1e6 * (st.time - t_start) / static_cast<double>(steps),
                1e6 * min_stable, static_cast<long long>(st.critical_element), st.step_calibration, st.energy.kinetic,
                st.energy.strain_energy, st.energy.contact_work, static_cast<long long>(st.nodes_in_contact),
                static_cast<long long>(changes), st.energy.relative_balance_error(), now - cpu);
    cpu = now;
    std::fflush(stdout);
  }
  if (!work_map.empty()) {
    std::FILE* out = std::fopen(work_map.c_str(), "w");
    if (out == nullptr) {
      std::fprintf(stderr, "--work-map %s: cannot write\n", work_map.c_str());
      return 2;
    }
    std::fprintf(out, "node,x,y,z,pressure_work,contact_work\n");
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto& x = solver.state().position;
      std::fprintf(out, "%lld,%.9g,%.9g,%.9g,%.6g,%.6g\n", static_cast<long long>(i), x(0, i), x(1, i), x(2, i),
                   pressure_work(i), contact_work(i));
    }
    std::fclose(out);
  }
  return 0;
}
