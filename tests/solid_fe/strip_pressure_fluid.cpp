// A 2D stand-in fluid for the solid's strip tests: a uniform pressure on the solid's interface
// segments, markers at their midpoints, force per unit depth p * length * n with n = z x (b - a)
// (the side the FE-only pressure pushes towards); optionally a viscous drag -c * length * v on
// the markers' velocity at the window start (so the loads depend on the solid's motion), and the
// pressure's sign flipped from a given time on. It has no state of its own, so it can restart
// (its restart file only says so). Exits like the stand-ins on any fault.
#include <cstdio>
#include <memory>

#include <CLI/CLI.hpp>
#include <Eigen/Geometry>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/coupling/endpoint.hpp"
#include "valvefsi/coupling/participant.hpp"
#include "valvefsi/coupling/restart_file.hpp"

int main(int argc, char** argv) {
  using namespace valvefsi::coupling;
  CLI::App app{"2D stand-in fluid: uniform pressure on the solid's interface segments"};
  std::string case_file, output;
  double pressure = 1.0;
  app.add_option("--case", case_file)->required();
  app.add_option("--output", output);
  double damping = 0.0, flip_time = 1e300;
  app.add_option("--pressure", pressure, "pressure (Pa) towards z x segment");
  app.add_option("--damping", damping, "drag per unit area (Pa s/m) on the markers' velocity");
  app.add_option("--flip-time", flip_time, "from this time (s) on the pressure pushes the other way");
  CLI11_PARSE(app, argc, argv);
  std::unique_ptr<Participant> p;
  try {
    const auto c = valvefsi::load_case(case_file);
    ParticipantOptions options;
    options.role = ParticipantRole::fluid;
    options.solver_name = "strip_pressure_fluid";
    options.solver_version = "1.0";
    options.endpoint = resolve_endpoint(c.coupling().endpoint(), output.empty() ? c.run().output_dir() : output);
    options.spatial_dimension = 2;
    options.can_checkpoint = true;
    options.can_restart = true;
    options.liveness.heartbeat_interval = std::chrono::duration<double>(c.coupling().heartbeat_interval_s());
    options.liveness.peer_timeout = std::chrono::duration<double>(c.coupling().peer_timeout_s());
    options.liveness.startup_timeout = std::chrono::duration<double>(c.coupling().startup_timeout_s());
    p = std::make_unique<Participant>(options);
    Eigen::Matrix3Xd forces;
    Eigen::VectorXd lengths;
    p->initialize_fluid([&](const InterfaceSurfaceData& s) {
      InterfacePoints points;
      const auto cells = s.cells.cols();
      points.positions.resize(3, cells);
      points.areas.resize(cells);
      forces = Eigen::Matrix3Xd::Zero(3, cells);
      lengths.resize(cells);
      for (Eigen::Index k = 0; k < cells; ++k) {
        const Eigen::Vector3d a = s.positions.col(s.cells(0, k)), b = s.positions.col(s.cells(1, k));
        points.positions.col(k) = 0.5 * (a + b);
        points.areas(k) = (b - a).norm();
        lengths(k) = points.areas(k);
        forces.col(k) = pressure * Eigen::Vector3d::UnitZ().cross(b - a);  // |b - a| * n
      }
      return points;
    });
    Window w;
    while (p->next_window(w)) {
      if (w.write_restart) {
        RestartWriter file(restart_file_path(w.restart_directory, p->name()));
        file.put_integer("stateless", 1);
        file.commit();
      }
      Eigen::Matrix3Xd loads = (w.time >= flip_time ? -1.0 : 1.0) * forces;
      if (damping > 0.0) loads -= damping * (w.motion.velocities.array().rowwise() * lengths.transpose().array()).matrix();
      p->complete_window(InterfaceLoads{loads}, 0.0);
    }
    p->finalize();
    return 0;
  } catch (const TransportError& e) {
    std::fprintf(stderr, "strip_pressure_fluid: %s\n", e.what());
    if (p) p->abort(e.what());
    return e.exit_code();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "strip_pressure_fluid: %s\n", e.what());
    if (p) p->abort(e.what());
    return 2;
  }
}
