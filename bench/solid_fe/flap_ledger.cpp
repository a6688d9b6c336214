// Diagnostic (docs/solid_fe.md, "The pressed flap"): the undamped MHGO flap of the energy-growth
// test pressed at 10 kPa onto a plane, with a per-step ledger written as CSV: step, energies
// (kinetic, strain, contact stored, booked works), the balance, the true energy error
// KE + U + U_contact - W_ext - KE0, and the free corner node's gap, speed and acceleration.
#include <algorithm>
#include <cmath>
#include <vector>
#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "test_meshes.hpp"
#include "valvefsi/solid/energy_growth_error.hpp"
#include "valvefsi/solid/mhgo.hpp"
#include "valvefsi/solid/shell_solver.hpp"

using namespace valvefsi::solid;

int main(int argc, char** argv) {
  CLI::App app("pressed-flap ledger");
  double fixed_step = 0, end = 0.03, pressure = 10e3, safety = 0.8, contact_factor = 0.1, growth = 0.002;
  int calibration = 2000, interval = 10;
  double look_ahead = 0;
  std::string out = "flap_ledger.csv";
  app.add_option("--fixed-step", fixed_step);
  app.add_option("--end", end);
  app.add_option("--pressure", pressure);
  app.add_option("--safety", safety);
  app.add_option("--contact-factor", contact_factor);
  app.add_option("--growth", growth);
  app.add_option("--calibration", calibration);
  app.add_option("--interval", interval, "re-estimate the step every this many steps");
  app.add_option("--look-ahead", look_ahead);
  app.add_option("--out", out);
  CLI11_PARSE(app, argc, argv);

  Mesh mesh = testing::rectangular_plate(0.01, 0.005, 10, 5, 0.25e-3);
  ShellModelOptions model_options;
  model_options.fixed_nodes = mesh.node_sets.at("left");
  SolverOptions options;
  options.time_step_calibration_interval = calibration;
  options.time_step_update_interval = interval;
  options.time_step_look_ahead = look_ahead;
  options.max_time_step_growth = growth;
  options.max_energy_balance_error = 0.2;
  options.fixed_time_step = fixed_step;
  options.time_step_safety = safety;
  options.contact_stiffness_factor = contact_factor;
  ShellSolver solver(build_shell_model(mesh, model_options), Material{Mhgo{}}, options);
  solver.set_pressure([pressure](double t) { return -pressure * std::min(1.0, t / 1e-3); });
  const Plane plane{Eigen::Vector3d(0, 0, -0.3e-3), Eigen::Vector3d(0, 0, 1)};
  solver.add_contact_plane(plane);

  const Eigen::VectorXd mass = solver.elements().nodal_mass();
  const Eigen::VectorXd half = solver.elements().contact_half_thickness();
  const Eigen::Index corner = testing::grid_node(10, 0, 10), corner2 = testing::grid_node(10, 5, 10);
  std::FILE* f = std::fopen(out.c_str(), "w");
  std::fprintf(f, "step,t,dt,stable,calib,elem,kinetic,strain,contact_stored,w_int,w_ext,w_contact,balance,true_error,"
                  "in_contact,corner_gap,corner_vz,corner_az,corner_ke,corner2_ke,sum_ma2\n");
  std::vector<Eigen::Matrix3Xd> recent;  // the last positions, for the report at a stop
  solver.set_step_observer([&](const SolverState& s) {
    recent.push_back(s.position);
    if (recent.size() > 4) recent.erase(recent.begin());
    const double k = contact_factor * s.contact_omega2;
    double stored = 0, sum_ma2 = 0;
    Eigen::Vector3d a_corner = Eigen::Vector3d::Zero();
    for (Eigen::Index i = 0; i < s.position.cols(); ++i) {
      const double gap = (s.position.col(i) - plane.point).dot(plane.normal) - half(i);
      if (gap < 0 && !solver.elements().fixed()[static_cast<std::size_t>(i)]) stored += 0.5 * k * mass(i) * gap * gap;
      if (solver.elements().fixed()[static_cast<std::size_t>(i)]) continue;
      const Eigen::Vector3d a = (s.external_force.col(i) + s.contact_force.col(i) - s.internal_force.col(i)) / mass(i);
      sum_ma2 += mass(i) * a.squaredNorm() * s.last_step * s.last_step / 8.0;
      if (i == corner) a_corner = a;
    }
    const auto& e = s.energy;
    const double true_error = e.kinetic + e.strain_energy + stored - e.external_work - e.initial_kinetic;
    const double gap = (s.position.col(corner) - plane.point).dot(plane.normal) - half(corner);
    std::fprintf(f, "%lld,%.9g,%.6g,%.6g,%.4g,%lld,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%lld,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n",
                 static_cast<long long>(s.step), s.time, s.last_step, s.stable_step, s.step_calibration,
                 static_cast<long long>(s.critical_element), e.kinetic, e.strain_energy, stored, e.internal_work,
                 e.external_work, e.contact_work, e.balance(), true_error, static_cast<long long>(s.nodes_in_contact), gap,
                 s.velocity(2, corner), a_corner.z(), 0.5 * mass(corner) * s.velocity.col(corner).squaredNorm(),
                 0.5 * mass(corner2) * s.velocity.col(corner2).squaredNorm(), sum_ma2);
  });
  int code = 0;
  try {
    for (int w = 1; w * 1e-4 <= end + 1e-12; ++w) solver.advance_window(w * 1e-4);
  } catch (const EnergyGrowthError& e) {
    std::printf("%s\n", e.what());
    code = 3;
    // Which elements changed most over the last steps.
    std::vector<Eigen::VectorXd> stress(recent.size()), strain(recent.size());
    for (std::size_t k = 0; k < recent.size(); ++k) solver.elements().element_fields(recent[k], stress[k], strain[k]);
    const Eigen::VectorXd jump = (strain.back() - strain[strain.size() - 2]).cwiseAbs();
    std::vector<Eigen::Index> order(static_cast<std::size_t>(jump.size()));
    for (Eigen::Index i = 0; i < jump.size(); ++i) order[static_cast<std::size_t>(i)] = i;
    std::sort(order.begin(), order.end(), [&](auto a, auto b) { return jump(a) > jump(b); });
    for (int j = 0; j < 6; ++j) {
      const auto el = order[static_cast<std::size_t>(j)];
      std::printf("element %lld nodes %lld %lld %lld: log strain", static_cast<long long>(el),
                  static_cast<long long>(mesh.triangles[static_cast<std::size_t>(el)][0]),
                  static_cast<long long>(mesh.triangles[static_cast<std::size_t>(el)][1]),
                  static_cast<long long>(mesh.triangles[static_cast<std::size_t>(el)][2]));
      for (std::size_t k = 0; k < recent.size(); ++k) std::printf(" %.4g", strain[k](el));
      std::printf("  stress (kPa)");
      for (std::size_t k = 0; k < recent.size(); ++k) std::printf(" %.4g", stress[k](el) * 1e-3);
      std::printf("\n");
    }
    for (const auto node : {corner, corner - 1, corner + 11, corner + 10}) {
      std::printf("node %lld:", static_cast<long long>(node));
      for (std::size_t k = 0; k < recent.size(); ++k)
        std::printf(" [%.5g %.5g %.5g]mm", recent[k](0, node) * 1e3, recent[k](1, node) * 1e3, recent[k](2, node) * 1e3);
      std::printf("\n");
    }
  }
  std::fclose(f);
  std::printf("end t = %.6g s, %lld steps, balance error of largest %.3g\n", solver.state().time,
              static_cast<long long>(solver.state().step), solver.state().energy.balance_error_of_largest());
  return code;
}
