// standin_fluid_pressure: a fluid that pushes on the solid's surface with a uniform pressure
// (force = p * area * e_z on each marker), markers at the centroids of the solid's triangles.
// The total force it returns is therefore p times the surface area, exactly; the conservative
// mapping must deliver the same total to the solid. Speaks the protocol like fluid_sph would.

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <cstdlib>
#include <limits>

#include <Eigen/Geometry>

#include "standin_common.hpp"

int main(int argc, char** argv) {
  CLI::App app{"stand-in fluid: uniform pressure on markers at the solid's triangle centroids"};
  valvefsi::standins::StandinSettings common;
  double pressure = 100.0;
  double proposed_window = 0.0;
  valvefsi::standins::add_common_options(app, common);
  app.add_option("--pressure", pressure, "pressure pushing along +z (Pa)");
  app.add_option("--propose-window", proposed_window, "max_stable_window to propose (s), 0 = none");
  CLI11_PARSE(app, argc, argv);

  // Under mpirun only rank 0 takes part, as rank 0 of an MPI fluid gathers and scatters the
  // interface data; the other ranks have nothing to do here. Open MPI names the rank in the
  // environment, so the stand-in needs no MPI library to prove the launcher's mpirun path.
  if (const char* rank = std::getenv("OMPI_COMM_WORLD_RANK"); rank != nullptr && std::string(rank) != "0") {
    const char* size = std::getenv("OMPI_COMM_WORLD_SIZE");
    spdlog::info("standin_fluid_pressure: MPI rank {} of {}: idle (rank 0 takes part)", rank, size ? size : "?");
    return 0;
  }

  std::unique_ptr<valvefsi::coupling::Participant> participant;
  return valvefsi::standins::run_guarded("standin_fluid_pressure", participant, [&] {
    participant = std::make_unique<valvefsi::coupling::Participant>(valvefsi::standins::participant_options(
        common, valvefsi::coupling::ParticipantRole::fluid, "standin_fluid_pressure"));
    Eigen::VectorXd areas;
    participant->initialize_fluid([&](const valvefsi::coupling::InterfaceSurfaceData& surface) {
      valvefsi::coupling::InterfacePoints points;
      const auto cells = surface.cells.cols();
      points.positions.resize(3, cells);
      points.areas.resize(cells);
      for (Eigen::Index c = 0; c < cells; ++c) {
        const Eigen::Vector3d a = surface.positions.col(surface.cells(0, c));
        const Eigen::Vector3d b = surface.positions.col(surface.cells(1, c));
        const Eigen::Vector3d d = surface.positions.col(surface.cells(2, c));
        points.positions.col(c) = (a + b + d) / 3.0;
        points.areas(c) = 0.5 * (b - a).cross(d - a).norm();
      }
      areas = points.areas;
      return points;
    });
    valvefsi::coupling::Window window;
    while (participant->next_window(window)) {
      valvefsi::standins::simulate_step(common, window.index);
      valvefsi::coupling::InterfaceLoads loads{Eigen::Matrix3Xd::Zero(3, areas.size())};
      loads.forces.row(2) = pressure * areas.transpose();
      if (common.nan_at_window >= 0 && window.index == static_cast<std::uint64_t>(common.nan_at_window)) {
        loads.forces(1, 2) = std::numeric_limits<double>::quiet_NaN();
      }
      participant->complete_window(loads, proposed_window);
    }
    participant->finalize();
  });
}
