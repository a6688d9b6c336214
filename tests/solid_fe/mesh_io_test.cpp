// Mesh file: a written mesh reads back identically; bad content is rejected with the field named.
#include <filesystem>

#include <gtest/gtest.h>

#include "test_meshes.hpp"

namespace valvefsi::solid {
namespace {

TEST(MeshIo, RoundTrip) {
  Mesh mesh = testing::rectangular_plate(0.01, 0.005, 3, 2, 0.25e-3);
  mesh.element_sets["leaflet_0"] = {0, 1, 2};
  mesh.element_set_types["leaflet_0"] = "triangle";
  mesh.symmetry_planes["left"] = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0)};
  mesh.contact_planes["coaptation"] = {Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, -1, 0)};
  const auto file = std::filesystem::temp_directory_path() / "solid_mesh_roundtrip.mesh.h5";
  write_mesh(file, mesh);
  const Mesh back = read_mesh(file);
  EXPECT_EQ(back.nodes, mesh.nodes);
  EXPECT_EQ(back.triangles, mesh.triangles);
  EXPECT_EQ(back.triangle_thickness, mesh.triangle_thickness);
  EXPECT_EQ(back.triangle_circumferential, mesh.triangle_circumferential);
  EXPECT_EQ(back.node_sets, mesh.node_sets);
  EXPECT_EQ(back.element_sets, mesh.element_sets);
  EXPECT_EQ(back.element_set_types.at("leaflet_0"), "triangle");
  EXPECT_EQ(back.symmetry_planes.at("left").normal, Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(back.contact_planes.at("coaptation").point, Eigen::Vector3d(0, 1, 0));
  std::filesystem::remove(file);
}

TEST(MeshIo, BadIndexIsNamed) {
  Mesh mesh = testing::rectangular_plate(0.01, 0.005, 3, 2, 0.25e-3);
  mesh.triangles[4][1] = 99;
  try {
    validate_mesh(mesh, "plate.mesh.h5");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("/mesh/triangles[4][1] = 99"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_mesh("/nonexistent/x.mesh.h5"), std::runtime_error);
}

}  // namespace
}  // namespace valvefsi::solid
