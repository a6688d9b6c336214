// Validation (run explicitly): the valve's brick leaflets under the FE-only pressure next to the
// shell on the same case, for a few ms; prints step sizes, cost per step and leaflet motion.
//   VALVEFSI_HEX_VALVE_MESH  mesh with hexahedra (scripts/valve_scene/generate.py --elements hexahedra)
//   VALVEFSI_HEX_VALVE_CASE  case for the shell, the waveform and the material
//                            (default cases/fe-mhgo-sector-coarse.textproto)
//   VALVEFSI_HEX_VALVE_MS    simulated milliseconds (default 5)
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>

#include <gtest/gtest.h>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/case/pressure_waveform.hpp"
#include "valvefsi/solid/case_setup.hpp"
#include "valvefsi/solid/hexahedron_solver.hpp"
#include "valvefsi/solid/shell_solver.hpp"

namespace valvefsi::solid {
namespace {

double mean_radius(const Eigen::Matrix3Xd& x, const std::vector<std::int64_t>& nodes) {
  double r = 0;
  for (const auto n : nodes) r += std::hypot(x(0, n), x(1, n));
  return r / static_cast<double>(nodes.size());
}

struct RunSummary {
  std::int64_t steps = 0;
  double cpu_s = 0, first_dt = 0, last_dt = 0, radius0 = 0, radius = 0, peak_strain = 0, peak_stress = 0, error = 0;
  double surface_strain = 0, surface_stress = 0;  // bricks: on the faces
};

template <class Solver>
RunSummary run(Solver& solver, const std::vector<std::int64_t>& free_edge, double end_time, const char* name) {
  RunSummary s;
  solver.advance_window(0.0);
  s.first_dt = solver.state().stable_step;
  s.radius0 = mean_radius(solver.state().position, free_edge);
  const std::clock_t start = std::clock();
  for (int w = 1; w * 5e-4 <= end_time + 1e-12; ++w) {
    solver.advance_window(w * 5e-4);
    std::printf("%s t = %.2f ms: dt %.3g us (element %lld), free-edge mean radius %.3f mm, balance error %.2e\n", name,
                solver.state().time * 1e3, solver.state().stable_step * 1e6,
                static_cast<long long>(solver.state().critical_element),
                mean_radius(solver.state().position, free_edge) * 1e3, solver.state().energy.relative_balance_error());
  }
  s.cpu_s = static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC;
  s.steps = solver.state().step;
  s.last_dt = solver.state().stable_step;
  s.radius = mean_radius(solver.state().position, free_edge);
  s.error = solver.state().energy.relative_balance_error();
  if constexpr (requires { solver.state().energy.hourglass_energy; }) {
    const auto& e = solver.state().energy;
    std::printf("%s: strain energy %.3e J, hourglass energy %.3e J (%.1f %% of the stored energy)\n", name,
                e.strain_energy, e.hourglass_energy, 100 * e.hourglass_energy / (e.strain_energy + e.hourglass_energy));
  }
  Eigen::VectorXd stress, strain;
  solver.element_fields(stress, strain);
  s.peak_stress = stress.maxCoeff();
  s.peak_strain = strain.maxCoeff();
  if constexpr (requires { solver.surface_fields(stress, strain); }) {
    solver.surface_fields(stress, strain);
    s.surface_stress = stress.maxCoeff();
    s.surface_strain = strain.maxCoeff();
  }
  return s;
}

TEST(HexahedronValve, SectorOpensLikeTheShell) {
  const char* mesh_env = std::getenv("VALVEFSI_HEX_VALVE_MESH");
  if (mesh_env == nullptr) GTEST_SKIP() << "set VALVEFSI_HEX_VALVE_MESH to a mesh with hexahedra";
  const char* case_env = std::getenv("VALVEFSI_HEX_VALVE_CASE");
  const std::filesystem::path case_file =
      case_env ? std::filesystem::path(case_env) : std::filesystem::path(VALVEFSI_SOURCE_DIR) / "cases/fe-mhgo-sector-coarse.textproto";
  const double end_time = (std::getenv("VALVEFSI_HEX_VALVE_MS") ? std::atof(std::getenv("VALVEFSI_HEX_VALVE_MS")) : 5.0) * 1e-3;
  const cases::Case c = load_case(case_file);
  const PressureWaveform waveform(c.waveform(), case_file.string());
  const auto pressure = [&waveform](double t) { return waveform.transvalvular_pressure(t); };

  cases::Case brick_case = c;
  brick_case.mutable_solid()->set_mesh_file(std::filesystem::absolute(mesh_env).string());
  brick_case.mutable_solid()->set_element_family(cases::SolidCase::HEXAHEDRON);
  // The FE-only cases switch to implicit once settled (AUTOMATIC); bricks have no tangent, and
  // the first milliseconds compared here are explicit in both.
  brick_case.mutable_solid()->set_time_integration(cases::SolidCase::EXPLICIT);
  brick_case.mutable_solid()->clear_settled_filter_time_s();
  SolidSetup bricks = setup_from_case(brick_case, case_file);
  for (const auto& note : bricks.notes) std::printf("bricks: %s\n", note.c_str());
  bricks.solver->set_pressure_waveform(pressure);
  const RunSummary b = run(bricks.hexahedron_solver(), bricks.mesh.node_sets.at("free_edge"), end_time, "bricks");

  SolidSetup shells = setup_from_case(c, case_file);
  shells.solver->set_pressure_waveform(pressure);
  const RunSummary s = run(shells.shell_solver(), shells.mesh.node_sets.at("free_edge"), end_time, "shell");

  for (const auto& [name, r, elements] : {std::tuple{"bricks", b, bricks.mesh.hexahedra.size()},
                                          std::tuple{"shell", s, shells.mesh.triangles.size()}}) {
    std::printf("%s (%zu elements): %lld steps, dt %.3g -> %.3g us, CPU %.3f ms/step (%.2f us/element), "
                "free-edge radius %.3f -> %.3f mm, peak log strain %.3f, peak stress %.3g MPa (brick faces: %.3f, %.3g MPa), "
                "balance error %.1e\n",
                name, elements, static_cast<long long>(r.steps), r.first_dt * 1e6, r.last_dt * 1e6,
                1e3 * r.cpu_s / static_cast<double>(r.steps),
                1e6 * r.cpu_s / static_cast<double>(r.steps) / static_cast<double>(elements), r.radius0 * 1e3,
                r.radius * 1e3, r.peak_strain, r.peak_stress * 1e-6, r.surface_strain, r.surface_stress * 1e-6, r.error);
  }
  EXPECT_GT(b.radius, b.radius0);  // both open
  EXPECT_GT(s.radius, s.radius0);
  EXPECT_LT(b.error, 0.05);
}

}  // namespace
}  // namespace valvefsi::solid
