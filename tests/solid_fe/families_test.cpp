// Shell and bricks through the program: the same pressurised leaflet-like plate (MHGO, clamped on
// three sides like an attachment edge, one free edge) run by `solid_fe --fe-only` once as shell
// triangles and once as one layer of bricks; the free-edge midpoint's deflection must agree
// within 5 % (issue 3, item 7). The brick run also exercises the brick field output.
#include <hdf5.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <sys/wait.h>

#include "hexahedron/hex_test_meshes.hpp"
#include "test_meshes.hpp"

namespace valvefsi::solid {
namespace {

constexpr double kWidth = 0.01, kHeight = 0.008, kThickness = 0.25e-3;  // circumferential x radial x t (m)
constexpr int kNx = 10, kNy = 8;

std::vector<double> read_doubles(const std::filesystem::path& file, const std::string& dataset) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return {};
  const hid_t d = H5Dopen2(f, dataset.c_str(), H5P_DEFAULT);
  std::vector<double> out;
  if (d >= 0) {
    const hid_t space = H5Dget_space(d);
    out.resize(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
    H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data());
    H5Sclose(space);
    H5Dclose(d);
  }
  H5Fclose(f);
  return out;
}

bool has_dataset(const std::filesystem::path& file, const std::string& dataset) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return false;
  const bool found = H5Lexists(f, dataset.c_str(), H5P_DEFAULT) > 0;
  H5Fclose(f);
  return found;
}

// Runs the plate as `family` and returns the mean z of the monitored free-edge midpoint node(s)
// at the last sample (the bricks' pair mean is the mid-surface).
double free_edge_deflection(const std::string& family, std::string& log) {
  const auto dir = std::filesystem::temp_directory_path() / ("solid_families_test_" + family);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  Mesh mesh;
  const bool bricks = family == "HEXAHEDRON";
  if (bricks) {
    mesh = testing::box_mesh(kWidth, kHeight, kThickness, kNx, kNy, 1);
    for (const char* edge : {"x0", "x1", "y0"}) {
      for (const auto n : mesh.node_sets.at(edge)) mesh.node_sets["attachment"].push_back(n);
    }
    mesh.node_sets["tip"] = {testing::box_node(kNx / 2, kNy, 0, kNx, kNy), testing::box_node(kNx / 2, kNy, 1, kNx, kNy)};
  } else {
    mesh = testing::rectangular_plate(kWidth, kHeight, kNx, kNy, kThickness);
    for (const char* edge : {"left", "right", "bottom"}) {
      for (const auto n : mesh.node_sets.at(edge)) mesh.node_sets["attachment"].push_back(n);
    }
    mesh.node_sets["tip"] = {testing::grid_node(kNx / 2, kNy, kNx)};
  }
  write_mesh(dir / "plate.mesh.h5", mesh);
  // 8 mmHg ramped over 2 ms, then held; mass damping settles it by 25 ms.
  std::ofstream(dir / "case.textproto")
      << "run { end_time: 0.025 snapshot_interval: 0.025 series_interval: 0.001 fe_only: true }\n"
      << "waveform { period_s: 0.8 time_s: [0, 0.002, 0.4] ventricular_pressure_mmHg: [0, 8, 8] "
         "aortic_pressure_mmHg: [0, 0, 0] }\n"
      << "solid { mesh_file: \"plate.mesh.h5\" element_family: " << family
      << " material: MHGO mhgo { d_per_kPa: 1e-4 } mass_damping_per_s: 1500 monitor_node_sets: \"tip\" }\n";
  const std::string command = std::string(SOLID_FE_EXECUTABLE) + " --case " + (dir / "case.textproto").string() +
                              " --output " + (dir / "out").string() + " > " + (dir / "log.txt").string() + " 2>&1";
  const int status = std::system(command.c_str());
  std::ifstream in(dir / "log.txt");
  log.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return std::nan("");
  const auto fields = dir / "out" / "solid_fields.h5";
  EXPECT_TRUE(has_dataset(fields, bricks ? "/mesh/hexahedra" : "/mesh/triangles")) << family;
  const auto strain = read_doubles(fields, "/snapshots/000001/max_principal_log_strain");
  EXPECT_EQ(strain.size(), bricks ? static_cast<std::size_t>(kNx * kNy) : static_cast<std::size_t>(2 * kNx * kNy));
  const auto positions = read_doubles(dir / "out" / "solid_series.h5", "/monitor/tip/position");
  const auto series_time = read_doubles(dir / "out" / "solid_series.h5", "/time");
  const std::size_t per_sample = positions.size() / series_time.size();
  const auto z_at = [&](std::size_t sample) {
    double z = 0;
    for (std::size_t k = 0; k < per_sample / 3; ++k) z += positions[sample * per_sample + 3 * k + 2];
    return z / static_cast<double>(per_sample / 3) - (bricks ? 0.5 * kThickness : 0.0);
  };
  const double last = z_at(series_time.size() - 1), earlier = z_at(series_time.size() - 6);
  EXPECT_NEAR(last, earlier, 0.01 * std::abs(last)) << family << ": not settled (5 ms before the end)";
  return last;
}

TEST(SolidFamilies, ShellAndBricksAgreeOnAPressurisedLeafletLikePlate) {
  std::string shell_log, brick_log;
  const double w_shell = free_edge_deflection("SHELL", shell_log);
  const double w_bricks = free_edge_deflection("HEXAHEDRON", brick_log);
  std::printf("leaflet-like plate, 8 mmHg: free-edge midpoint deflection %.4f mm (shell), %.4f mm (bricks): %+.2f %%\n",
              w_shell * 1e3, w_bricks * 1e3, 100 * (w_bricks / w_shell - 1));
  ASSERT_TRUE(std::isfinite(w_shell)) << shell_log;
  ASSERT_TRUE(std::isfinite(w_bricks)) << brick_log;
  EXPECT_GT(w_shell, kThickness);  // a large deflection, as a leaflet's
  EXPECT_NEAR(w_bricks / w_shell, 1.0, 0.05);
}

}  // namespace
}  // namespace valvefsi::solid
