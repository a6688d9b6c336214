// standin_fluid_damper: a second, different fluid for the swap test. Markers at the solid's
// nodes and at the midpoints of its cell edges; each pushes with a pressure minus a viscous
// damping of the normal motion, f = (p - c v_z) * area * e_z, where area = the marker's share
// of the surface. A plate on a spring under it settles at z = p A / k.

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <map>
#include <utility>

#include <Eigen/Geometry>

#include "standin_common.hpp"

int main(int argc, char** argv) {
  CLI::App app{"stand-in fluid: pressure plus normal damping on markers at nodes and edge midpoints"};
  valvefsi::standins::StandinSettings common;
  double pressure = 100.0;
  double damping = 50.0;
  valvefsi::standins::add_common_options(app, common);
  app.add_option("--pressure", pressure, "pressure pushing along +z (Pa)");
  app.add_option("--damping", damping, "damping coefficient (Pa s/m)")->check(CLI::NonNegativeNumber);
  CLI11_PARSE(app, argc, argv);

  std::unique_ptr<valvefsi::coupling::Participant> participant;
  return valvefsi::standins::run_guarded("standin_fluid_damper", participant, [&] {
    participant = std::make_unique<valvefsi::coupling::Participant>(valvefsi::standins::participant_options(
        common, valvefsi::coupling::ParticipantRole::fluid, "standin_fluid_damper"));
    Eigen::VectorXd areas;
    participant->initialize_fluid([&](const valvefsi::coupling::InterfaceSurfaceData& surface) {
      // Each triangle gives 1/6 of its area to each corner and 1/6 to each edge midpoint
      // (the area is only a weight here; the total is what matters).
      std::vector<Eigen::Vector3d> positions;
      std::vector<double> weights;
      for (Eigen::Index n = 0; n < surface.positions.cols(); ++n) {
        positions.emplace_back(surface.positions.col(n));
        weights.push_back(0.0);
      }
      std::map<std::pair<int, int>, std::size_t> midpoint;
      for (Eigen::Index c = 0; c < surface.cells.cols(); ++c) {
        const Eigen::Vector3d a = surface.positions.col(surface.cells(0, c));
        const Eigen::Vector3d b = surface.positions.col(surface.cells(1, c));
        const Eigen::Vector3d d = surface.positions.col(surface.cells(2, c));
        const double share = 0.5 * (b - a).cross(d - a).norm() / 6.0;
        for (int k = 0; k < 3; ++k) {
          const int p = surface.cells(k, c), q = surface.cells((k + 1) % 3, c);
          weights[static_cast<std::size_t>(p)] += share;
          const auto key = std::minmax(p, q);
          auto [it, inserted] = midpoint.try_emplace({key.first, key.second}, positions.size());
          if (inserted) {
            positions.emplace_back(0.5 * (surface.positions.col(p) + surface.positions.col(q)));
            weights.push_back(0.0);
          }
          weights[it->second] += share;
        }
      }
      valvefsi::coupling::InterfacePoints points;
      points.positions.resize(3, static_cast<Eigen::Index>(positions.size()));
      points.areas.resize(static_cast<Eigen::Index>(positions.size()));
      for (std::size_t i = 0; i < positions.size(); ++i) {
        points.positions.col(static_cast<Eigen::Index>(i)) = positions[i];
        points.areas(static_cast<Eigen::Index>(i)) = weights[i];
      }
      areas = points.areas;
      return points;
    });
    valvefsi::coupling::Window window;
    while (participant->next_window(window)) {
      valvefsi::standins::simulate_step(common, window.index);
      valvefsi::coupling::InterfaceLoads loads{Eigen::Matrix3Xd::Zero(3, areas.size())};
      loads.forces.row(2) = (pressure - damping * window.motion.velocities.row(2).array()) * areas.transpose().array();
      participant->complete_window(loads, 0.0);
    }
    participant->finalize();
  });
}
