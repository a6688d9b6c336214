// Reading and writing the leaflet mesh file (docs/mesh-format.md) with the HDF5 C API.
#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "valvefsi/solid/hdf5_handle.hpp"
#include "valvefsi/solid/mesh.hpp"

namespace valvefsi::solid {
namespace {

struct Reader {
  std::string file;
  hid_t root;

  [[noreturn]] void fail(const std::string& what) const { throw std::runtime_error(file + ": " + what); }

  bool exists(const std::string& path) const {
    // Check each level, since H5Lexists fails on a missing intermediate group.
    std::size_t pos = 1;
    while (true) {
      const std::size_t next = path.find('/', pos);
      const std::string prefix = path.substr(0, next);
      if (H5Lexists(root, prefix.c_str(), H5P_DEFAULT) <= 0) return false;
      if (next == std::string::npos) return true;
      pos = next + 1;
    }
  }

  // Reads an n-dimensional dataset as a flat vector, checking its rank and trailing extent.
  template <class T>
  std::vector<T> read(const std::string& path, int rank, hsize_t columns, hsize_t& rows) const {
    if (!exists(path)) fail(fmt::format("dataset {} is missing", path));
    H5Handle ds(H5Dopen2(root, path.c_str(), H5P_DEFAULT), H5Dclose);
    if (!ds.valid()) fail(fmt::format("cannot open dataset {}", path));
    H5Handle space(H5Dget_space(ds.get()), H5Sclose);
    const int actual_rank = H5Sget_simple_extent_ndims(space.get());
    hsize_t dims[2] = {0, 0};
    H5Sget_simple_extent_dims(space.get(), dims, nullptr);
    if (actual_rank != rank || (rank == 2 && dims[1] != columns)) {
      fail(fmt::format("dataset {} has shape [{}{}], expected [n{}]", path, dims[0],
                       actual_rank == 2 ? fmt::format("][{}", dims[1]) : "",
                       rank == 2 ? fmt::format("][{}", columns) : ""));
    }
    rows = dims[0];
    std::vector<T> data(static_cast<std::size_t>(rows * (rank == 2 ? columns : 1)));
    const hid_t type = std::is_same_v<T, double> ? H5T_NATIVE_DOUBLE : H5T_NATIVE_INT64;
    if (!data.empty() && H5Dread(ds.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0) {
      fail(fmt::format("cannot read dataset {}", path));
    }
    return data;
  }

  std::vector<std::string> members(const std::string& group) const {
    std::vector<std::string> names;
    if (!exists(group)) return names;
    H5Handle g(H5Gopen2(root, group.c_str(), H5P_DEFAULT), H5Gclose);
    H5G_info_t info;
    H5Gget_info(g.get(), &info);
    for (hsize_t i = 0; i < info.nlinks; ++i) {
      const ssize_t size = H5Lget_name_by_idx(g.get(), ".", H5_INDEX_NAME, H5_ITER_INC, i, nullptr, 0, H5P_DEFAULT);
      std::string name(static_cast<std::size_t>(size), '\0');
      H5Lget_name_by_idx(g.get(), ".", H5_INDEX_NAME, H5_ITER_INC, i, name.data(), name.size() + 1, H5P_DEFAULT);
      names.push_back(name);
    }
    return names;
  }

  std::vector<double> double_attribute(const std::string& object, const char* name, std::size_t n) const {
    H5Handle attr(H5Aopen_by_name(root, object.c_str(), name, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    if (!attr.valid()) fail(fmt::format("{} has no attribute '{}'", object, name));
    H5Handle space(H5Aget_space(attr.get()), H5Sclose);
    const hssize_t count = H5Sget_simple_extent_npoints(space.get());
    if (count != static_cast<hssize_t>(n)) {
      fail(fmt::format("{} attribute '{}' has {} values, expected {}", object, name, count, n));
    }
    std::vector<double> values(n);
    H5Aread(attr.get(), H5T_NATIVE_DOUBLE, values.data());
    return values;
  }

  std::string string_attribute(const std::string& object, const char* name) const {
    if (H5Aexists_by_name(root, object.c_str(), name, H5P_DEFAULT) <= 0) return {};
    H5Handle attr(H5Aopen_by_name(root, object.c_str(), name, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    H5Handle type(H5Aget_type(attr.get()), H5Tclose);
    if (H5Tis_variable_str(type.get()) > 0) {
      char* text = nullptr;
      H5Handle mem(H5Tcopy(H5T_C_S1), H5Tclose);
      H5Tset_size(mem.get(), H5T_VARIABLE);
      H5Tset_cset(mem.get(), H5Tget_cset(type.get()));  // h5py writes UTF-8
      H5Aread(attr.get(), mem.get(), &text);
      std::string result = text != nullptr ? text : "";
      H5free_memory(text);
      return result;
    }
    const std::size_t size = H5Tget_size(type.get());
    std::string result(size, '\0');
    H5Aread(attr.get(), type.get(), result.data());
    result.erase(std::find(result.begin(), result.end(), '\0'), result.end());
    return result;
  }
};

Eigen::Matrix3Xd as_columns(const std::vector<double>& flat, hsize_t rows) {
  Eigen::Matrix3Xd m(3, static_cast<Eigen::Index>(rows));
  std::memcpy(m.data(), flat.data(), flat.size() * sizeof(double));  // row-major [n][3] = column-major 3 x n
  return m;
}

// Reads a [n][3] float64 dataset as a 3 x n matrix.
Eigen::Matrix3Xd read_columns(const Reader& r, const std::string& path) {
  hsize_t rows = 0;
  const std::vector<double> flat = r.read<double>(path, 2, 3, rows);
  return as_columns(flat, rows);
}

Plane read_plane(const Reader& r, const std::string& path) {
  const auto p = r.double_attribute(path, "point", 3);
  const auto n = r.double_attribute(path, "normal", 3);
  Plane plane;
  plane.point = {p[0], p[1], p[2]};
  plane.normal = {n[0], n[1], n[2]};
  if (plane.normal.norm() < 1e-12) r.fail(fmt::format("{} attribute 'normal' is zero", path));
  plane.normal.normalize();
  return plane;
}

}  // namespace

Mesh read_mesh(const std::filesystem::path& file) {
  if (!std::filesystem::exists(file)) throw std::runtime_error(file.string() + ": mesh file not found");
  H5Handle h(H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!h.valid()) throw std::runtime_error(file.string() + ": not an HDF5 file");
  const Reader r{file.string(), h.get()};
  if (!r.exists("/mesh")) r.fail("group /mesh is missing (not a valvefsi mesh file)");
  const std::string format = r.string_attribute("/mesh", "format");
  if (format != "valvefsi-mesh") {
    r.fail(fmt::format("/mesh attribute format = '{}': expected 'valvefsi-mesh'", format));
  }

  Mesh mesh;
  hsize_t rows = 0;
  mesh.nodes = read_columns(r, "/mesh/nodes");
  if (r.exists("/mesh/triangles")) {
    const auto tri = r.read<std::int64_t>("/mesh/triangles", 2, 3, rows);
    mesh.triangles.resize(rows);
    std::memcpy(mesh.triangles.data(), tri.data(), tri.size() * sizeof(std::int64_t));
    hsize_t n = 0;
    mesh.triangle_thickness = r.read<double>("/mesh/triangle_thickness", 1, 1, n);
    mesh.triangle_circumferential =
        read_columns(r, "/mesh/triangle_axes/circumferential");
    mesh.triangle_radial = read_columns(r, "/mesh/triangle_axes/radial");
  }
  if (r.exists("/mesh/hexahedra")) {
    const auto hex = r.read<std::int64_t>("/mesh/hexahedra", 2, 8, rows);
    mesh.hexahedra.resize(rows);
    std::memcpy(mesh.hexahedra.data(), hex.data(), hex.size() * sizeof(std::int64_t));
    mesh.hexahedron_circumferential =
        read_columns(r, "/mesh/hexahedron_axes/circumferential");
    mesh.hexahedron_radial = read_columns(r, "/mesh/hexahedron_axes/radial");
  }
  for (const auto& name : r.members("/mesh/node_sets")) {
    hsize_t n = 0;
    mesh.node_sets[name] = r.read<std::int64_t>("/mesh/node_sets/" + name, 1, 1, n);
  }
  for (const auto& name : r.members("/mesh/element_sets")) {
    hsize_t n = 0;
    const std::string path = "/mesh/element_sets/" + name;
    mesh.element_sets[name] = r.read<std::int64_t>(path, 1, 1, n);
    std::string type = r.string_attribute(path, "element_type");
    if (type.empty()) type = "triangle";
    if (type != "triangle" && type != "hexahedron") {
      r.fail(fmt::format("{} attribute element_type = '{}': allowed 'triangle' or 'hexahedron'", path, type));
    }
    mesh.element_set_types[name] = type;
  }
  for (const auto& name : r.members("/mesh/symmetry_planes")) {
    mesh.symmetry_planes[name] = read_plane(r, "/mesh/symmetry_planes/" + name);
  }
  for (const auto& name : r.members("/mesh/contact_planes")) {
    mesh.contact_planes[name] = read_plane(r, "/mesh/contact_planes/" + name);
  }
  validate_mesh(mesh, file.string());
  return mesh;
}

void validate_mesh(const Mesh& mesh, const std::string& source) {
  const std::int64_t n = mesh.num_nodes();
  auto fail = [&](const std::string& what) { throw std::invalid_argument(source + ": " + what); };
  if (!mesh.nodes.allFinite()) fail("/mesh/nodes contains a non-finite coordinate");
  const std::size_t t = mesh.triangles.size();
  for (std::size_t e = 0; e < t; ++e) {
    for (int a = 0; a < 3; ++a) {
      const std::int64_t i = mesh.triangles[e][a];
      if (i < 0 || i >= n) fail(fmt::format("/mesh/triangles[{}][{}] = {}: allowed 0..{}", e, a, i, n - 1));
    }
  }
  if (mesh.triangle_thickness.size() != t) {
    fail(fmt::format("/mesh/triangle_thickness has {} values for {} triangles", mesh.triangle_thickness.size(), t));
  }
  for (std::size_t e = 0; e < t; ++e) {
    if (!(mesh.triangle_thickness[e] > 0.0)) {
      fail(fmt::format("/mesh/triangle_thickness[{}] = {}: allowed > 0", e, mesh.triangle_thickness[e]));
    }
  }
  if (static_cast<std::size_t>(mesh.triangle_circumferential.cols()) != t ||
      static_cast<std::size_t>(mesh.triangle_radial.cols()) != t) {
    fail(fmt::format("/mesh/triangle_axes: {} circumferential and {} radial vectors for {} triangles",
                     mesh.triangle_circumferential.cols(), mesh.triangle_radial.cols(), t));
  }
  for (std::size_t e = 0; e < t; ++e) {
    const double len = mesh.triangle_circumferential.col(static_cast<Eigen::Index>(e)).norm();
    if (std::abs(len - 1.0) > 1e-3) {
      fail(fmt::format("/mesh/triangle_axes/circumferential[{}] has length {}: must be a unit vector", e, len));
    }
  }
  for (const auto& h : mesh.hexahedra) {
    for (const std::int64_t i : h) {
      if (i < 0 || i >= n) fail(fmt::format("/mesh/hexahedra: node index {}: allowed 0..{}", i, n - 1));
    }
  }
  for (const auto& [name, nodes] : mesh.node_sets) {
    for (const std::int64_t i : nodes) {
      if (i < 0 || i >= n) fail(fmt::format("/mesh/node_sets/{}: node {}: allowed 0..{}", name, i, n - 1));
    }
  }
  for (const auto& [name, elements] : mesh.element_sets) {
    const auto type_it = mesh.element_set_types.find(name);
    const bool hex = type_it != mesh.element_set_types.end() && type_it->second == "hexahedron";
    const auto count = static_cast<std::int64_t>(hex ? mesh.hexahedra.size() : t);
    for (const std::int64_t i : elements) {
      if (i < 0 || i >= count) {
        fail(fmt::format("/mesh/element_sets/{}: element {}: allowed 0..{}", name, i, count - 1));
      }
    }
  }
}

namespace {

void write_dataset(hid_t parent, const std::string& name, const void* data, hid_t type, hsize_t rows,
                   hsize_t columns) {
  const hsize_t dims[2] = {rows, columns};
  H5Handle space(H5Screate_simple(columns == 0 ? 1 : 2, dims, nullptr), H5Sclose);
  H5Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(lcpl.get(), 1);
  H5Handle ds(H5Dcreate2(parent, name.c_str(), type, space.get(), lcpl.get(), H5P_DEFAULT, H5P_DEFAULT), H5Dclose);
  if (!ds.valid()) throw std::runtime_error("cannot create dataset " + name);
  if (rows > 0) H5Dwrite(ds.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
}

void write_string_attribute(hid_t object, const char* name, const std::string& value) {
  H5Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), value.size() + 1);
  H5Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  H5Handle attr(H5Acreate2(object, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  H5Awrite(attr.get(), type.get(), value.c_str());
}

void write_double_attribute(hid_t object, const char* name, const double* values, hsize_t n) {
  H5Handle space(H5Screate_simple(1, &n, nullptr), H5Sclose);
  H5Handle attr(H5Acreate2(object, name, H5T_NATIVE_DOUBLE, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  H5Awrite(attr.get(), H5T_NATIVE_DOUBLE, values);
}

void write_planes(hid_t file, const std::string& group, const std::map<std::string, Plane>& planes) {
  for (const auto& [name, plane] : planes) {
    H5Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
    H5Pset_create_intermediate_group(lcpl.get(), 1);
    H5Handle g(H5Gcreate2(file, (group + "/" + name).c_str(), lcpl.get(), H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    write_double_attribute(g.get(), "point", plane.point.data(), 3);
    write_double_attribute(g.get(), "normal", plane.normal.data(), 3);
  }
}

}  // namespace

void write_mesh(const std::filesystem::path& file, const Mesh& mesh) {
  H5Handle h(H5Fcreate(file.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
  if (!h.valid()) throw std::runtime_error(file.string() + ": cannot create mesh file");
  {
    H5Handle g(H5Gcreate2(h.get(), "/mesh", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    write_string_attribute(g.get(), "format", "valvefsi-mesh");
    const int version = 1;
    H5Handle space(H5Screate(H5S_SCALAR), H5Sclose);
    H5Handle attr(H5Acreate2(g.get(), "version", H5T_NATIVE_INT, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    H5Awrite(attr.get(), H5T_NATIVE_INT, &version);
  }
  const hid_t f = h.get();
  const auto cols = [](const Eigen::Matrix3Xd& m) { return static_cast<hsize_t>(m.cols()); };
  write_dataset(f, "/mesh/nodes", mesh.nodes.data(), H5T_NATIVE_DOUBLE, cols(mesh.nodes), 3);
  if (!mesh.triangles.empty()) {
    write_dataset(f, "/mesh/triangles", mesh.triangles.data(), H5T_NATIVE_INT64, mesh.triangles.size(), 3);
    write_dataset(f, "/mesh/triangle_thickness", mesh.triangle_thickness.data(), H5T_NATIVE_DOUBLE,
                  mesh.triangle_thickness.size(), 0);
    write_dataset(f, "/mesh/triangle_axes/circumferential", mesh.triangle_circumferential.data(),
                  H5T_NATIVE_DOUBLE, cols(mesh.triangle_circumferential), 3);
    write_dataset(f, "/mesh/triangle_axes/radial", mesh.triangle_radial.data(), H5T_NATIVE_DOUBLE,
                  cols(mesh.triangle_radial), 3);
  }
  if (!mesh.hexahedra.empty()) {
    write_dataset(f, "/mesh/hexahedra", mesh.hexahedra.data(), H5T_NATIVE_INT64, mesh.hexahedra.size(), 8);
    write_dataset(f, "/mesh/hexahedron_axes/circumferential", mesh.hexahedron_circumferential.data(),
                  H5T_NATIVE_DOUBLE, cols(mesh.hexahedron_circumferential), 3);
    write_dataset(f, "/mesh/hexahedron_axes/radial", mesh.hexahedron_radial.data(), H5T_NATIVE_DOUBLE,
                  cols(mesh.hexahedron_radial), 3);
  }
  for (const auto& [name, nodes] : mesh.node_sets) {
    write_dataset(f, "/mesh/node_sets/" + name, nodes.data(), H5T_NATIVE_INT64, nodes.size(), 0);
  }
  for (const auto& [name, elements] : mesh.element_sets) {
    const std::string path = "/mesh/element_sets/" + name;
    write_dataset(f, path, elements.data(), H5T_NATIVE_INT64, elements.size(), 0);
    H5Handle ds(H5Dopen2(f, path.c_str(), H5P_DEFAULT), H5Dclose);
    const auto it = mesh.element_set_types.find(name);
    write_string_attribute(ds.get(), "element_type", it != mesh.element_set_types.end() ? it->second : "triangle");
  }
  write_planes(f, "/mesh/symmetry_planes", mesh.symmetry_planes);
  write_planes(f, "/mesh/contact_planes", mesh.contact_planes);
}

}  // namespace valvefsi::solid
