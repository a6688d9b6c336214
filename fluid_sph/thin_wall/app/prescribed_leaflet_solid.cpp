// prescribed_leaflet_solid: a solid participant whose leaflet mesh (the case's solid.mesh_file,
// the nodes and triangles solid_fe would send) moves by a prescribed opening and closing and
// ignores the loads (issue 6 item 6: the fluid's leaflet model through a whole valve motion
// with no structural feedback). The motion blends the rest shape X into an open shape Y (a
// snapshot of an FE-only run, same mesh):
//   x(t) = X + s(t) (Y - X),  s = 0 until --open-start, rises as (1 - cos(pi tau)) / 2 over
//   --opening, holds 1 for --hold, falls the same way over --closing, then 0.
// Attachment nodes are fixed in both shapes, so they stay fixed; a blend of two shapes inside
// the contact cylinder and on one side of the coaptation plane stays there. The loads the fluid
// returns are logged (and written by the coupler to coupling_series.h5).
#include <CLI/CLI.hpp>
#include <hdf5.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "standin_common.hpp"
#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/solid/mesh.hpp"
#include "valvefsi/solid/solid_interface.hpp"

namespace {

struct Schedule {
  double open_start = 1e-3, opening = 6e-3, hold = 2e-3, closing = 6e-3;

  // (s, ds/dt) at time t.
  std::pair<double, double> at(double t) const {
    const double pi = std::numbers::pi;
    auto ramp = [&](double tau, double duration) {
      return std::pair{0.5 * (1.0 - std::cos(pi * tau)), 0.5 * pi * std::sin(pi * tau) / duration};
    };
    const double t1 = open_start, t2 = t1 + opening, t3 = t2 + hold, t4 = t3 + closing;
    if (t <= t1 || t >= t4) return {0.0, 0.0};
    if (t < t2) return ramp((t - t1) / opening, opening);
    if (t <= t3) return {1.0, 0.0};
    const auto [s, v] = ramp((t - t3) / closing, closing);
    return {1.0 - s, -v};
  }
};

// /snapshots/<name>/position of a solid_fe solid_fields.h5 ([nodes, 3] row-major) and its time.
Eigen::Matrix3Xd read_snapshot(const std::filesystem::path& file, const std::string& name, Eigen::Index nodes,
                               double& time) {
  const std::string where = fmt::format("{}: /snapshots/{}/position", file.string(), name);
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) throw std::runtime_error(fmt::format("{}: cannot open (a solid_fields.h5 of an FE-only run)", file.string()));
  const std::string path = "/snapshots/" + name + "/position";
  const hid_t d = H5Dopen2(f, path.c_str(), H5P_DEFAULT);
  if (d < 0) {
    H5Fclose(f);
    throw std::runtime_error(where + ": no such dataset (--open-snapshot names a group under /snapshots)");
  }
  const hid_t space = H5Dget_space(d);
  hsize_t dims[2] = {0, 0};
  const int rank = H5Sget_simple_extent_dims(space, dims, nullptr);
  H5Sclose(space);
  if (rank != 2 || dims[1] != 3 || static_cast<Eigen::Index>(dims[0]) != nodes) {
    H5Dclose(d);
    H5Fclose(f);
    throw std::runtime_error(fmt::format("{}: shape [{}, {}], allowed [{}, 3] (the case's mesh)", where, dims[0],
                                         rank == 2 ? dims[1] : 0, nodes));
  }
  Eigen::Matrix3Xd x(3, nodes);  // column-major 3 x N = row-major N x 3
  H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, x.data());
  H5Dclose(d);
  time = std::nan("");
  const std::string group = "/snapshots/" + name;
  if (H5Aexists_by_name(f, group.c_str(), "time", H5P_DEFAULT) > 0) {
    const hid_t a = H5Aopen_by_name(f, group.c_str(), "time", H5P_DEFAULT, H5P_DEFAULT);
    H5Aread(a, H5T_NATIVE_DOUBLE, &time);
    H5Aclose(a);
  }
  H5Fclose(f);
  return x;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"prescribed-motion leaflet solid: the case's leaflet mesh opened and closed on a schedule"};
  valvefsi::standins::StandinSettings common;
  valvefsi::standins::add_common_options(app, common);
  std::string open_shape, open_snapshot;
  Schedule schedule;
  double proposed_window = 0.0;
  app.add_option("--open-shape", open_shape, "solid_fields.h5 of an FE-only run on the same mesh")->required();
  app.add_option("--open-snapshot", open_snapshot, "group under /snapshots holding the open shape, e.g. 000015")
      ->required();
  app.add_option("--open-start", schedule.open_start, "time the opening starts (s)")->check(CLI::NonNegativeNumber);
  app.add_option("--opening", schedule.opening, "opening duration (s)")->check(CLI::PositiveNumber);
  app.add_option("--hold", schedule.hold, "time held open (s)")->check(CLI::NonNegativeNumber);
  app.add_option("--closing", schedule.closing, "closing duration (s)")->check(CLI::PositiveNumber);
  app.add_option("--propose-window", proposed_window, "window to propose (s), 0 = the case's");
  CLI11_PARSE(app, argc, argv);

  std::unique_ptr<valvefsi::coupling::Participant> participant;
  return valvefsi::standins::run_guarded("prescribed_leaflet_solid", participant, [&] {
    const auto c = valvefsi::load_case(common.case_file);
    std::filesystem::path mesh_file = c.solid().mesh_file();
    if (mesh_file.is_relative()) mesh_file = std::filesystem::path(common.case_file).parent_path() / mesh_file;
    const auto mesh = valvefsi::solid::read_mesh(mesh_file);
    const auto interface = valvefsi::solid::surface_interface(mesh);
    double snapshot_time = 0.0;
    const Eigen::Matrix3Xd open = read_snapshot(open_shape, open_snapshot, mesh.num_nodes(), snapshot_time);
    const Eigen::Matrix3Xd rest = mesh.nodes;
    const Eigen::Matrix3Xd travel = open - rest;
    spdlog::info("prescribed_leaflet_solid: {} nodes, {} triangles; open shape {} (t = {} s), largest travel {:.3f} mm; "
                 "opening {}-{} s, held to {} s, closed at {} s",
                 mesh.num_nodes(), mesh.num_triangles(), open_snapshot, snapshot_time,
                 travel.colwise().norm().maxCoeff() * 1e3, schedule.open_start, schedule.open_start + schedule.opening,
                 schedule.open_start + schedule.opening + schedule.hold,
                 schedule.open_start + schedule.opening + schedule.hold + schedule.closing);

    valvefsi::coupling::InterfaceSurfaceData surface;
    surface.positions = rest;
    surface.nodes_per_cell = interface.nodes_per_cell;
    surface.cells = interface.cells;
    surface.node_areas = interface.node_areas;
    surface.node_thickness = interface.node_thickness;
    auto motion_at = [&](double t) {
      const auto [s, ds] = schedule.at(t);
      return valvefsi::coupling::InterfaceMotion{rest + s * travel, ds * travel};
    };

    participant = std::make_unique<valvefsi::coupling::Participant>(valvefsi::standins::participant_options(
        common, valvefsi::coupling::ParticipantRole::solid, "prescribed_leaflet_solid"));
    participant->initialize_solid(surface, motion_at(0.0));
    valvefsi::coupling::Window window;
    double work = 0.0;  // work of the fluid's loads on the leaflet (J): each window's load x its displacement
    while (participant->next_window(window)) {
      const auto [s0, v0] = schedule.at(window.time);
      const auto [s1, v1] = schedule.at(window.end());
      (void)v0;
      (void)v1;
      const Eigen::Vector3d total = window.loads.forces.rowwise().sum();
      work += (window.loads.forces.cwiseProduct((s1 - s0) * travel)).sum();
      if (window.index % 200 == 0) {
        spdlog::info("t = {:.5f} s: opening fraction {:.3f}, force on the leaflet ({:.4e}, {:.4e}, {:.4e}) N, "
                     "work {:.4e} J",
                     window.end(), s1, total.x(), total.y(), total.z(), work);
      }
      participant->complete_window(motion_at(window.end()), proposed_window);
    }
    spdlog::info("prescribed_leaflet_solid: done, work of the fluid's loads {:.4e} J", work);
    participant->finalize();
  });
}
