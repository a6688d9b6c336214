#pragma once
// The leaflet mesh as read from a *.mesh.h5 file (format: docs/mesh-format.md).
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace valvefsi::solid {

// A plane given by a point on it and its unit normal.
struct Plane {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

struct Mesh {
  Eigen::Matrix3Xd nodes;                                // reference coordinates (m), one per column
  std::vector<std::array<std::int64_t, 3>> triangles;    // shell elements, normal by right-hand rule
  std::vector<double> triangle_thickness;                // (m)
  Eigen::Matrix3Xd triangle_circumferential;             // unit, in the element plane
  Eigen::Matrix3Xd triangle_radial;                      // unit, in the plane, normal to circumferential
  std::vector<std::array<std::int64_t, 8>> hexahedra;    // optional bricks
  Eigen::Matrix3Xd hexahedron_circumferential;
  Eigen::Matrix3Xd hexahedron_radial;
  std::map<std::string, std::vector<std::int64_t>> node_sets;
  std::map<std::string, std::vector<std::int64_t>> element_sets;
  std::map<std::string, std::string> element_set_types;  // "triangle" | "hexahedron"
  std::map<std::string, Plane> symmetry_planes;
  std::map<std::string, Plane> contact_planes;

  std::int64_t num_nodes() const { return nodes.cols(); }
  std::int64_t num_triangles() const { return static_cast<std::int64_t>(triangles.size()); }
};

// Reads and checks a mesh file; errors name the file, the dataset and the offending value.
Mesh read_mesh(const std::filesystem::path& file);
// Writes a mesh in the same format (used by tests and tools).
void write_mesh(const std::filesystem::path& file, const Mesh& mesh);

// Throws std::invalid_argument naming `source` if indices, thickness or axes are invalid.
void validate_mesh(const Mesh& mesh, const std::string& source);

}  // namespace valvefsi::solid
