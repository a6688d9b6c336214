#include "valvefsi/fluid/output.hpp"

#include <fmt/format.h>
#include <hdf5.h>

#include <fstream>
#include <stdexcept>

namespace valvefsi::fluid {
namespace {

void check(herr_t status, const std::string& what) {
  if (status < 0) throw std::runtime_error("HDF5: " + what + " failed");
}

hid_t check_id(hid_t id, const std::string& what) {
  if (id < 0) throw std::runtime_error("HDF5: " + what + " failed");
  return id;
}

// Writes a rows x columns array (columns = 1: a vector) as dataset `name` under `location`,
// creating intermediate groups.
template <class T>
void write_dataset(hid_t location, const std::string& name, const T* data, hsize_t rows, hsize_t columns, hid_t type) {
  const hsize_t dims[2] = {rows, columns};
  const hid_t space = check_id(H5Screate_simple(columns == 1 ? 1 : 2, dims, nullptr), "dataspace " + name);
  const hid_t links = H5Pcreate(H5P_LINK_CREATE);
  H5Pset_create_intermediate_group(links, 1);
  const hid_t set = check_id(H5Dcreate2(location, name.c_str(), type, space, links, H5P_DEFAULT, H5P_DEFAULT), "create " + name);
  if (rows * columns > 0) check(H5Dwrite(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "write " + name);
  H5Dclose(set);
  H5Pclose(links);
  H5Sclose(space);
}

}  // namespace

template <int D>
SnapshotWriter<D>::SnapshotWriter(const std::filesystem::path& directory, bool writes) : directory_(directory), writes_(writes) {
  if (!writes_) return;
  std::filesystem::create_directories(directory_);
  const auto file = directory_ / "fluid_particles.h5";
  const hid_t h = check_id(H5Fcreate(file.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), "create " + file.string());
  H5Fclose(h);
}

template <int D>
void SnapshotWriter<D>::write(const FluidSolver<D>& solver) {
  const auto& p = solver.particles();
  // Mirror images are scratch of the symmetry planes, rebuilt every step: not written; nor the
  // halo of a split run (the neighbour writes its own particles).
  const auto* slabs = solver.decomposition();
  std::vector<std::size_t> written;
  const auto [first, last] = solver.owned_range();
  for (std::size_t i = first; i < last; ++i)
    if (!is_mirror(p.kind[i])) written.push_back(i);
  if (slabs != nullptr)
    for (std::size_t i = solver.grid().cell_start(solver.grid().cell_count()); i < p.size(); ++i)
      if (p.kind[i] == Kind::lost) written.push_back(i);
  std::size_t n = written.size();
  std::vector<double> position(3 * n, 0.0), velocity(3 * n, 0.0);
  std::vector<float> pressure(n), density(n);
  std::vector<int> kind(n);
  std::vector<unsigned> id(n);
  const double background = solver.settings().background_pressure + solver.plate_pressure_level();
  std::size_t j = 0;
  for (const std::size_t i : written) {
    for (int d = 0; d < D; ++d) {
      position[3 * j + d] = p.position[d][i];
      velocity[3 * j + d] = p.velocity[d][i];
    }
    pressure[j] = static_cast<float>(p.pressure[i] - background);
    density[j] = static_cast<float>(solver.settings().rest_density + p.density_excess[i]);
    kind[j] = static_cast<int>(p.kind[i]);
    id[j] = p.id[i];
    ++j;
  }
  if (slabs != nullptr) {
    // Rank 0 writes everyone's particles, in rank order.
    auto gather = [&]<class T>(std::vector<T>& values) {
      const std::vector<double> mine(values.begin(), values.end());
      const std::vector<double> all = slabs->gather(mine);
      values.assign(all.begin(), all.end());
    };
    gather(position);
    gather(velocity);
    gather(pressure);
    gather(density);
    gather(kind);
    gather(id);
    n = pressure.size();
  }
  if (!writes_) return;
  const auto file = directory_ / "fluid_particles.h5";
  const hid_t h = check_id(H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), "open " + file.string());
  const std::string group = fmt::format("snapshot_{:06d}", entries_.size());
  const hid_t g = check_id(H5Gcreate2(h, group.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "group " + group);
  const double t = solver.time();
  const hid_t scalar = H5Screate(H5S_SCALAR);
  const hid_t attribute = H5Acreate2(g, "time", H5T_NATIVE_DOUBLE, scalar, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(attribute, H5T_NATIVE_DOUBLE, &t);
  H5Aclose(attribute);
  H5Sclose(scalar);
  write_dataset(g, "position", position.data(), n, 3, H5T_NATIVE_DOUBLE);
  write_dataset(g, "velocity", velocity.data(), n, 3, H5T_NATIVE_DOUBLE);
  write_dataset(g, "pressure", pressure.data(), n, 1, H5T_NATIVE_FLOAT);
  write_dataset(g, "density", density.data(), n, 1, H5T_NATIVE_FLOAT);
  write_dataset(g, "kind", kind.data(), n, 1, H5T_NATIVE_INT);
  write_dataset(g, "id", id.data(), n, 1, H5T_NATIVE_UINT);
  H5Gclose(g);
  H5Fclose(h);
  entries_.push_back({t, n});
  write_xdmf();
}

template <int D>
void SnapshotWriter<D>::write_xdmf() const {
  std::ofstream x(directory_ / "fluid_particles.xmf");
  x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n <Domain>\n"
    << "  <Grid Name=\"particles\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (std::size_t k = 0; k < entries_.size(); ++k) {
    const auto& e = entries_[k];
    const std::string g = fmt::format("fluid_particles.h5:/snapshot_{:06d}", k);
    x << fmt::format("   <Grid Name=\"t{}\" GridType=\"Uniform\">\n    <Time Value=\"{:.9g}\"/>\n", k, e.time)
      << fmt::format("    <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{}\"/>\n", e.particles)
      << fmt::format("    <Geometry GeometryType=\"XYZ\"><DataItem Dimensions=\"{} 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">{}/position</DataItem></Geometry>\n",
                     e.particles, g);
    x << fmt::format("    <Attribute Name=\"velocity\" AttributeType=\"Vector\" Center=\"Node\"><DataItem Dimensions=\"{} 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">{}/velocity</DataItem></Attribute>\n",
                     e.particles, g);
    for (const char* name : {"pressure", "density"})
      x << fmt::format("    <Attribute Name=\"{}\" AttributeType=\"Scalar\" Center=\"Node\"><DataItem Dimensions=\"{}\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">{}/{}</DataItem></Attribute>\n",
                       name, e.particles, g, name);
    x << fmt::format("    <Attribute Name=\"kind\" AttributeType=\"Scalar\" Center=\"Node\"><DataItem Dimensions=\"{}\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">{}/kind</DataItem></Attribute>\n",
                     e.particles, g);
    x << "   </Grid>\n";
  }
  x << "  </Grid>\n </Domain>\n</Xdmf>\n";
}

void SeriesWriter::add_column(const std::string& path, int components) {
  if (!time_.empty()) throw std::logic_error("SeriesWriter: column " + path + " added after the first sample");
  columns_.push_back({path, components, {}});
}

void SeriesWriter::append(double time, const std::vector<double>& values) {
  std::size_t expected = 0;
  for (const auto& c : columns_) expected += static_cast<std::size_t>(c.components);
  if (values.size() != expected)
    throw std::logic_error(fmt::format("SeriesWriter: {} values for {} column components", values.size(), expected));
  time_.push_back(time);
  std::size_t k = 0;
  for (auto& c : columns_)
    for (int j = 0; j < c.components; ++j) c.data.push_back(values[k++]);
}

void SeriesWriter::set_attribute(const std::string& name, double value) {
  for (auto& a : attributes_)
    if (a.first == name) {
      a.second = value;
      return;
    }
  attributes_.emplace_back(name, value);
}

void SeriesWriter::flush() const {
  std::filesystem::create_directories(file_.parent_path().empty() ? "." : file_.parent_path());
  const hid_t h = check_id(H5Fcreate(file_.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), "create " + file_.string());
  write_dataset(h, "time", time_.data(), time_.size(), 1, H5T_NATIVE_DOUBLE);
  for (const auto& c : columns_)
    write_dataset(h, c.path, c.data.data(), time_.size(), static_cast<hsize_t>(c.components), H5T_NATIVE_DOUBLE);
  for (const auto& [name, value] : attributes_) {
    const hid_t scalar = H5Screate(H5S_SCALAR);
    const hid_t attribute = H5Acreate2(h, name.c_str(), H5T_NATIVE_DOUBLE, scalar, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(attribute, H5T_NATIVE_DOUBLE, &value);
    H5Aclose(attribute);
    H5Sclose(scalar);
  }
  H5Fclose(h);
}

template class SnapshotWriter<2>;
template class SnapshotWriter<3>;

}  // namespace valvefsi::fluid
