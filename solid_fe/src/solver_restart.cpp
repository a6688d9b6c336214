#include "valvefsi/solid/solver_restart.hpp"

#include <span>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

#include "valvefsi/coupling/restart_file.hpp"

namespace valvefsi::solid {
namespace {

// 3 x n matrices that may be empty (bricks' hourglass force for shells, the Lanczos vector
// before the first calibration, the tie arrays without a tie).
void put_matrix(coupling::RestartWriter& file, std::string_view name, const Eigen::Matrix3Xd& m) {
  file.put(name, std::span<const double>(m.data(), static_cast<std::size_t>(m.size())));
}

Eigen::Matrix3Xd get_matrix(const coupling::RestartReader& file, std::string_view name) {
  const auto values = file.doubles(name);
  if (values.size() % 3 != 0) {
    throw std::runtime_error(fmt::format("{}: entry '{}' has {} values, not 3 per node", file.file().string(),
                                         name, values.size()));
  }
  return Eigen::Map<const Eigen::Matrix3Xd>(values.data(), 3, static_cast<Eigen::Index>(values.size() / 3));
}

Eigen::Matrix3Xd get_nodes(const coupling::RestartReader& file, std::string_view name, Eigen::Index nodes,
                           bool may_be_empty = false) {
  Eigen::Matrix3Xd m = get_matrix(file, name);
  if (m.cols() != nodes && !(may_be_empty && m.cols() == 0)) {
    throw std::runtime_error(fmt::format("{}: entry '{}' has {} nodes, the mesh has {}", file.file().string(), name,
                                         m.cols(), nodes));
  }
  return m;
}

constexpr const char* kEnergyNames[] = {"kinetic",      "internal_work",  "hourglass_work", "strain_energy",
                                        "hourglass_energy", "external_work", "damping_work", "contact_work",
                                        "tie_work",     "tie_energy",     "interface_work", "initial_kinetic"};

double* energy_field(EnergyBalance& e, int k) {
  double* fields[] = {&e.kinetic,      &e.internal_work, &e.hourglass_work, &e.strain_energy,
                      &e.hourglass_energy, &e.external_work, &e.damping_work, &e.contact_work,
                      &e.tie_work,     &e.tie_energy,    &e.interface_work, &e.initial_kinetic};
  return fields[k];
}

}  // namespace

void write_solver_restart(const ExplicitSolver& solver, coupling::RestartWriter& file) {
  const SolverState& s = solver.state();
  file.put_integer("solid/nodes", s.position.cols());
  file.put_integer("solid/is_hexahedron", std::string(solver.elements().family()) == "hexahedron" ? 1 : 0);
  file.put("solid/time", s.time);
  file.put_integer("solid/step", s.step);
  file.put("solid/position", s.position);
  file.put("solid/half_step_velocity", s.half_step_velocity);
  file.put("solid/velocity", s.velocity);
  file.put("solid/internal_force", s.internal_force);
  put_matrix(file, "solid/hourglass_force", s.hourglass_force);
  file.put("solid/external_force", s.external_force);
  file.put("solid/contact_force", s.contact_force);
  put_matrix(file, "solid/tie_force", s.tie_force);
  file.put_integer("solid/nodes_in_contact", s.nodes_in_contact);
  file.put("solid/last_step", s.last_step);
  file.put("solid/uncut_step", s.uncut_step);
  file.put("solid/stable_step", s.stable_step);
  file.put_integer("solid/critical_element", s.critical_element);
  EnergyBalance energy = s.energy;
  for (int k = 0; k < static_cast<int>(std::size(kEnergyNames)); ++k) {
    file.put(fmt::format("solid/energy/{}", kEnergyNames[k]), *energy_field(energy, k));
  }
  file.put("solid/energy/largest_energy", s.energy.largest_energy);
  file.put("solid/step_calibration", s.step_calibration);
  file.put("solid/highest_frequency", s.highest_frequency);
  file.put("solid/calibrated_step", s.calibrated_step);
  file.put("solid/element_step_at_calibration", s.element_step_at_calibration);
  file.put_integer("solid/calibrated_at_step", s.calibrated_at_step);
  file.put_integer("solid/stiffening_ahead", s.stiffening_ahead ? 1 : 0);
  file.put_integer("solid/calibration_iterations", s.calibration_iterations);
  put_matrix(file, "solid/power_vector", s.power_vector);
  file.put("solid/contact_omega2", s.contact_omega2);
  std::vector<std::int64_t> pairs;
  pairs.reserve(2 * s.contact_candidates.pairs.size());
  for (const auto& [node, element] : s.contact_candidates.pairs) {
    pairs.push_back(node);
    pairs.push_back(element);
  }
  file.put("solid/contact_candidates/pairs", std::span<const std::int64_t>(pairs));
  put_matrix(file, "solid/contact_candidates/positions_at_build", s.contact_candidates.positions_at_build);
  file.put_integer("solid/contact_candidates/rebuilds", s.contact_candidates.rebuilds);
  const std::vector<std::int64_t> tied(s.tie.tied.begin(), s.tie.tied.end());
  file.put("solid/tie/tied", std::span<const std::int64_t>(tied));
  put_matrix(file, "solid/tie/anchor", s.tie.anchor);
  file.put_integer("solid/tie/captures", s.tie.captures);
  file.put_integer("solid/tie/releases", s.tie.releases);
  file.put("solid/tie/peak_force", s.tie.peak_force);
  // Implicit dynamics and the automatic switch (ninth session): with the acceleration an implicit
  // continuation is bit for bit (the kept tangent is rebuilt by both runs, drop_kept_tangent).
  file.put("solid/energy/numerical_dissipation", s.energy.numerical_dissipation);
  file.put("solid/energy/load_step_dissipation", s.energy.load_step_dissipation);
  put_matrix(file, "solid/acceleration", s.acceleration);
  file.put("solid/implicit_step", s.implicit_step);
  file.put_integer("solid/newton_iterations", s.newton_iterations);
  file.put_integer("solid/implicit_phase", s.implicit_phase ? 1 : 0);
  file.put("solid/settled_since", s.settled_since);
  file.put("solid/implicit_switch_pressure", s.implicit_switch_pressure);
  file.put_integer("solid/switches", s.switches);
  put_matrix(file, "solid/slow_velocity", s.slow_velocity);
  file.put("solid/slow_kinetic", s.slow_kinetic);
  file.put_integer("solid/chatter_damped", s.chatter_damped ? 1 : 0);
  // The cost rule's books (fourteenth session).
  const double books[] = {s.explicit_step_at_switch, s.block_work, s.block_start, s.block_start_step,
                          static_cast<double>(s.phase_steps), static_cast<double>(s.cost_switches)};
  file.put("solid/cost_rule/books", std::span<const double>(books));
}

void write_solver_restart(const ExplicitSolver& solver, const std::filesystem::path& file) {
  coupling::RestartWriter writer(file);
  write_solver_restart(solver, writer);
  writer.commit();
}

void read_solver_restart(const coupling::RestartReader& file, ExplicitSolver& solver) {
  const Eigen::Index n = solver.elements().reference_positions().cols();
  const std::string name = file.file().string();
  if (file.integer("solid/nodes") != n) {
    throw std::runtime_error(fmt::format("{}: written for a mesh of {} nodes; this case's mesh has {}", name,
                                         file.integer("solid/nodes"), n));
  }
  const bool hexahedron = std::string(solver.elements().family()) == "hexahedron";
  if ((file.integer("solid/is_hexahedron") != 0) != hexahedron) {
    throw std::runtime_error(fmt::format("{}: written for {} elements; this case uses {}", name,
                                         hexahedron ? "shell" : "hexahedron", solver.elements().family()));
  }
  SolverState s = solver.state();  // keeps the shapes the solver set up
  s.time = file.scalar("solid/time");
  s.step = file.integer("solid/step");
  s.position = get_nodes(file, "solid/position", n);
  s.half_step_velocity = get_nodes(file, "solid/half_step_velocity", n);
  s.velocity = get_nodes(file, "solid/velocity", n);
  s.internal_force = get_nodes(file, "solid/internal_force", n);
  s.hourglass_force = get_nodes(file, "solid/hourglass_force", n, true);
  s.external_force = get_nodes(file, "solid/external_force", n);
  s.contact_force = get_nodes(file, "solid/contact_force", n);
  const Eigen::Matrix3Xd tie_force = get_nodes(file, "solid/tie_force", n, true);
  if (tie_force.cols() != s.tie_force.cols()) {
    throw std::runtime_error(fmt::format("{}: written {} a coaptation tie; this case has {}", name,
                                         tie_force.cols() > 0 ? "with" : "without",
                                         s.tie_force.cols() > 0 ? "one" : "none"));
  }
  s.tie_force = tie_force;
  s.nodes_in_contact = file.integer("solid/nodes_in_contact");
  s.last_step = file.scalar("solid/last_step");
  s.uncut_step = file.scalar("solid/uncut_step");
  s.stable_step = file.scalar("solid/stable_step");
  s.critical_element = file.integer("solid/critical_element");
  for (int k = 0; k < static_cast<int>(std::size(kEnergyNames)); ++k) {
    *energy_field(s.energy, k) = file.scalar(fmt::format("solid/energy/{}", kEnergyNames[k]));
  }
  // (files of session 4 have no largest_energy: the energy-growth scale then starts anew)
  s.energy.largest_energy = file.has("solid/energy/largest_energy") ? file.scalar("solid/energy/largest_energy") : 0.0;
  s.step_calibration = file.scalar("solid/step_calibration");
  s.highest_frequency = file.scalar("solid/highest_frequency");
  s.calibrated_step = file.scalar("solid/calibrated_step");
  s.element_step_at_calibration = file.scalar("solid/element_step_at_calibration");
  s.calibrated_at_step = file.integer("solid/calibrated_at_step");
  // (files before the sixth session have no look-ahead state)
  s.stiffening_ahead = file.has("solid/stiffening_ahead") && file.integer("solid/stiffening_ahead") != 0;
  s.calibration_iterations = static_cast<int>(file.integer("solid/calibration_iterations"));
  s.power_vector = get_nodes(file, "solid/power_vector", n, true);
  s.contact_omega2 = file.scalar("solid/contact_omega2");
  // (files before the ninth session: no implicit state; an implicit run recomputes the
  // acceleration and starts with its first step, an AUTOMATIC one starts explicit)
  if (file.has("solid/implicit_phase")) {
    s.energy.numerical_dissipation = file.scalar("solid/energy/numerical_dissipation");
    // (files before the seventeenth session: no load-step part booked yet)
    s.energy.load_step_dissipation = file.has("solid/energy/load_step_dissipation")
                                         ? file.scalar("solid/energy/load_step_dissipation")
                                         : 0.0;
    s.acceleration = get_nodes(file, "solid/acceleration", n, true);
    s.implicit_step = file.scalar("solid/implicit_step");
    s.newton_iterations = static_cast<int>(file.integer("solid/newton_iterations"));
    s.implicit_phase = file.integer("solid/implicit_phase") != 0;
    s.settled_since = file.scalar("solid/settled_since");
    s.implicit_switch_pressure = file.scalar("solid/implicit_switch_pressure");
    s.switches = file.integer("solid/switches");
  }
  // (files before the eleventh session: no filtered velocity; the filter restarts from v)
  if (file.has("solid/slow_velocity")) {
    s.slow_velocity = get_nodes(file, "solid/slow_velocity", n, true);
    s.slow_kinetic = file.scalar("solid/slow_kinetic");
    s.chatter_damped = file.integer("solid/chatter_damped") != 0;
  }
  // (files before the fourteenth session: no cost rule's books; an implicit phase in progress
  // is then not judged, the next one is)
  if (file.has("solid/cost_rule/books")) {
    const auto books = file.doubles("solid/cost_rule/books", 6);
    s.explicit_step_at_switch = books[0];
    s.block_work = books[1];
    s.block_start = books[2];
    s.block_start_step = books[3];
    s.phase_steps = static_cast<std::int64_t>(books[4]);  // (counts, exact in a double)
    s.cost_switches = static_cast<std::int64_t>(books[5]);
  }
  const auto pairs = file.integers("solid/contact_candidates/pairs");
  s.contact_candidates.pairs.clear();
  for (std::size_t k = 0; k + 1 < pairs.size(); k += 2) {
    s.contact_candidates.pairs.emplace_back(static_cast<std::int32_t>(pairs[k]), static_cast<std::int32_t>(pairs[k + 1]));
  }
  s.contact_candidates.positions_at_build = get_nodes(file, "solid/contact_candidates/positions_at_build", n, true);
  s.contact_candidates.rebuilds = file.integer("solid/contact_candidates/rebuilds");
  const auto tied = file.integers("solid/tie/tied", static_cast<std::ptrdiff_t>(s.tie.tied.size()));
  s.tie.tied.assign(tied.begin(), tied.end());
  const Eigen::Matrix3Xd anchor = get_matrix(file, "solid/tie/anchor");
  if (anchor.cols() != s.tie.anchor.cols()) {
    throw std::runtime_error(fmt::format("{}: entry 'solid/tie/anchor' has {} nodes, this case's tie {}", name,
                                         anchor.cols(), s.tie.anchor.cols()));
  }
  s.tie.anchor = anchor;
  s.tie.captures = file.integer("solid/tie/captures");
  s.tie.releases = file.integer("solid/tie/releases");
  s.tie.peak_force = file.scalar("solid/tie/peak_force");
  solver.restore(s);
}

void read_solver_restart(const std::filesystem::path& file, ExplicitSolver& solver) {
  const coupling::RestartReader reader(file);
  read_solver_restart(reader, solver);
}

}  // namespace valvefsi::solid
