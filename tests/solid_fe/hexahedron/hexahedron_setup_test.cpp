// Brick set-up from a case file: sets, material and bulk modulus, pressure faces, symmetry and
// messages that name the field.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "hex_test_meshes.hpp"
#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/solid/case_setup.hpp"
#include "valvefsi/solid/hexahedron_solver.hpp"

namespace valvefsi::solid {
namespace {

std::filesystem::path write_case(const std::string& name, const std::string& solid_block, bool with_bricks = true) {
  const auto dir = std::filesystem::temp_directory_path() / ("solid_hexahedron_setup_test_" + name);
  std::filesystem::create_directories(dir);
  Mesh mesh = testing::box_mesh(0.01, 0.005, 0.25e-3, 8, 4, 1);
  mesh.node_sets["attachment"] = mesh.node_sets.at("x0");
  mesh.element_sets["leaflet_0_hexahedra"] = {0, 1, 2, 3};
  mesh.element_set_types["leaflet_0_hexahedra"] = "hexahedron";
  mesh.symmetry_planes["bottom"] = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 1, 0)};
  if (!with_bricks) {
    mesh = testing::box_mesh(0.01, 0.005, 0.25e-3, 1, 1, 1);
    mesh.hexahedra.clear();
    mesh.hexahedron_circumferential.resize(3, 0);
    mesh.hexahedron_radial.resize(3, 0);
    mesh.triangles = {{0, 1, 3}};
    mesh.triangle_thickness = {1e-4};
    mesh.triangle_circumferential = Eigen::Vector3d::UnitX();
    mesh.triangle_radial = Eigen::Vector3d::UnitY();
  }
  write_mesh(dir / "bricks.mesh.h5", mesh);
  const auto case_file = dir / "bricks.textproto";
  std::ofstream(case_file) << "title: \"bricks\"\n"
                           << "run { end_time: 0.001 fe_only: true }\n"
                           << "waveform { period_s: 0.8 time_s: [0, 0.4] ventricular_pressure_mmHg: [10, 10] "
                              "aortic_pressure_mmHg: [0, 0] }\n"
                           << "solid { mesh_file: \"bricks.mesh.h5\" element_family: HEXAHEDRON " << solid_block
                           << " }\n";
  return case_file;
}

TEST(HexahedronSetup, BuildsTheSolverFromTheCase) {
  const auto file = write_case("ok", "material: OGDEN mhgo { d_per_kPa: 2e-5 }");
  const SolidSetup setup = setup_from_case(load_case(file), file);
  ASSERT_EQ(setup.element_family, ElementFamily::hexahedron);
  HexahedronSolver& solver = setup.hexahedron_solver();
  ASSERT_TRUE(std::holds_alternative<SolidOgden>(solver.material()));
  EXPECT_NEAR(bulk_modulus(solver.material()), 2.0 / 2e-8, 1.0);  // kappa = 2 / D
  EXPECT_EQ(setup.pressure_faces.size(), 32u);                          // every bottom face
  int fixed = 0;
  for (auto v : solver.model().fixed) fixed += v;
  EXPECT_EQ(fixed, 10);  // x = 0 face: 5 x 2 nodes
  // The nodes on the y = 0 mirror plane keep y = 0 under a pull along y.
  Eigen::Matrix3Xd pull = Eigen::Matrix3Xd::Zero(3, setup.mesh.num_nodes());
  pull.row(1).setConstant(-1e-3);
  solver.advance_window(1e-5, &pull);
  for (const auto n : setup.mesh.node_sets.at("y0")) EXPECT_EQ(solver.displacement()(1, n), 0.0);

  const auto only_set = write_case("set", "pressure_element_sets: \"leaflet_0_hexahedra\"");
  EXPECT_EQ(setup_from_case(load_case(only_set), only_set).pressure_faces.size(), 4u);
}

TEST(HexahedronSetup, MessagesNameTheField) {
  const auto bad_set = write_case("badset", "pressure_element_sets: \"nope\"");
  try {
    setup_from_case(load_case(bad_set), bad_set);
    FAIL();
  } catch (const CaseError& e) {
    EXPECT_NE(std::string(e.what()).find("solid.pressure_element_sets"), std::string::npos) << e.what();
  }
  const auto no_bricks = write_case("nobricks", "", false);
  try {
    setup_from_case(load_case(no_bricks), no_bricks);
    FAIL();
  } catch (const CaseError& e) {
    EXPECT_NE(std::string(e.what()).find("/mesh/hexahedra"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace valvefsi::solid
