#include "valvefsi/solid/solid_output.hpp"

#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>

namespace valvefsi::solid {
namespace {

void write_array(hid_t parent, const std::string& name, const double* data, hsize_t rows, hsize_t columns) {
  const hsize_t dims[2] = {rows, columns};
  H5Handle space(H5Screate_simple(columns == 0 ? 1 : 2, dims, nullptr), H5Sclose);
  H5Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(lcpl.get(), 1);
  H5Handle ds(H5Dcreate2(parent, name.c_str(), H5T_NATIVE_DOUBLE, space.get(), lcpl.get(), H5P_DEFAULT, H5P_DEFAULT),
              H5Dclose);
  if (!ds.valid()) throw std::runtime_error("solid output: cannot create dataset " + name);
  if (rows > 0) H5Dwrite(ds.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
}

void write_scalar_attribute(hid_t object, const char* name, double value) {
  H5Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  H5Handle attr(H5Acreate2(object, name, H5T_NATIVE_DOUBLE, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  H5Awrite(attr.get(), H5T_NATIVE_DOUBLE, &value);
}

}  // namespace

std::string restarted_output_suffix(const std::filesystem::path& dir, double restart_time) {
  if (!std::filesystem::exists(dir / "solid_series.h5") && !std::filesystem::exists(dir / "solid_fields.h5")) return "";
  return fmt::format("_t_{:.9f}", restart_time);
}

FieldWriter::FieldWriter(const std::filesystem::path& dir, const Mesh& mesh, ElementFamily family,
                         const std::string& suffix)
    : dir_(dir), stem_("solid_fields" + suffix), family_(family), num_nodes_(mesh.num_nodes()),
      num_elements_(family == ElementFamily::shell ? mesh.num_triangles()
                                                   : static_cast<std::int64_t>(mesh.hexahedra.size())) {
  std::filesystem::create_directories(dir_);
  const auto path = dir_ / (stem_ + ".h5");
  file_ = H5Handle(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
  if (!file_.valid()) throw std::runtime_error(path.string() + ": cannot create output file");
  write_array(file_.get(), "/mesh/nodes", mesh.nodes.data(), static_cast<hsize_t>(num_nodes_), 3);
  const bool shell = family_ == ElementFamily::shell;
  const hsize_t dims[2] = {static_cast<hsize_t>(num_elements_), shell ? 3u : 8u};
  H5Handle space(H5Screate_simple(2, dims, nullptr), H5Sclose);
  H5Handle ds(H5Dcreate2(file_.get(), shell ? "/mesh/triangles" : "/mesh/hexahedra", H5T_NATIVE_INT64, space.get(),
                         H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose);
  // Hexahedron node order 0-3 / 4-7 is XDMF's (and VTK's) Hexahedron order.
  H5Dwrite(ds.get(), H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT,
           shell ? static_cast<const void*>(mesh.triangles.data()) : static_cast<const void*>(mesh.hexahedra.data()));
}

void FieldWriter::write(const ExplicitSolver& solver, double& peak_stress, double& peak_log_strain) {
  const SolverState& s = solver.state();
  const std::string group = fmt::format("/snapshots/{:06d}", times_.size());
  const auto n = static_cast<hsize_t>(num_nodes_);
  const Eigen::Matrix3Xd u = solver.displacement();
  write_array(file_.get(), group + "/position", s.position.data(), n, 3);
  write_array(file_.get(), group + "/displacement", u.data(), n, 3);
  write_array(file_.get(), group + "/velocity", s.velocity.data(), n, 3);
  Eigen::VectorXd stress, strain;
  solver.element_fields(stress, strain);
  const auto t = static_cast<hsize_t>(num_elements_);
  write_array(file_.get(), group + "/max_principal_stress", stress.data(), t, 0);
  write_array(file_.get(), group + "/max_principal_log_strain", strain.data(), t, 0);
  {
    H5Handle g(H5Gopen2(file_.get(), group.c_str(), H5P_DEFAULT), H5Gclose);
    write_scalar_attribute(g.get(), "time", s.time);
  }
  H5Fflush(file_.get(), H5F_SCOPE_GLOBAL);
  peak_stress = stress.size() > 0 ? stress.maxCoeff() : 0.0;
  peak_log_strain = strain.size() > 0 ? strain.maxCoeff() : 0.0;
  times_.push_back(s.time);
  write_xdmf();
}

void FieldWriter::write_xdmf() const {
  const auto path = dir_ / (stem_ + ".xdmf");
  const auto tmp = dir_ / (stem_ + ".xdmf.tmp");
  {
    std::ofstream out(tmp);
    out << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n <Domain>\n"
        << "  <Grid Name=\"leaflets\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
    const bool shell = family_ == ElementFamily::shell;
    for (std::size_t k = 0; k < times_.size(); ++k) {
      const std::string g = fmt::format("{}.h5:/snapshots/{:06d}", stem_, k);
      const auto vec = [&](const char* name, const char* center) {
        return fmt::format(
            "    <Attribute Name=\"{0}\" AttributeType=\"Vector\" Center=\"{1}\">\n"
            "     <DataItem Dimensions=\"{2} 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">{3}/{0}</DataItem>\n"
            "    </Attribute>\n", name, center, num_nodes_, g);
      };
      const auto scalar = [&](const char* name) {
        return fmt::format(
            "    <Attribute Name=\"{0}\" AttributeType=\"Scalar\" Center=\"Cell\">\n"
            "     <DataItem Dimensions=\"{1}\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">{2}/{0}</DataItem>\n"
            "    </Attribute>\n", name, num_elements_, g);
      };
      out << fmt::format("   <Grid Name=\"t{}\" GridType=\"Uniform\">\n    <Time Value=\"{:.9g}\"/>\n", k, times_[k])
          << fmt::format("    <Topology TopologyType=\"{0}\" NumberOfElements=\"{1}\">\n"
                         "     <DataItem Dimensions=\"{1} {2}\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">"
                         "{4}.h5:/mesh/{3}</DataItem>\n    </Topology>\n",
                         shell ? "Triangle" : "Hexahedron", num_elements_, shell ? 3 : 8,
                         shell ? "triangles" : "hexahedra", stem_)
          << fmt::format("    <Geometry GeometryType=\"XYZ\">\n"
                         "     <DataItem Dimensions=\"{} 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">"
                         "{}/position</DataItem>\n    </Geometry>\n", num_nodes_, g)
          << vec("displacement", "Node") << vec("velocity", "Node") << scalar("max_principal_stress")
          << scalar("max_principal_log_strain") << "   </Grid>\n";
    }
    out << "  </Grid>\n </Domain>\n</Xdmf>\n";
  }
  std::filesystem::rename(tmp, path);
}

SeriesWriter::SeriesWriter(std::filesystem::path dir,
                           std::vector<std::pair<std::string, std::vector<std::int64_t>>> monitors,
                           const std::string& suffix)
    : dir_(std::move(dir)), stem_("solid_series" + suffix), monitors_(std::move(monitors)), monitor_positions_(monitors_.size()) {
  std::filesystem::create_directories(dir_);
}

void SeriesWriter::sample(const ExplicitSolver& solver, double pressure_Pa) {
  const SolverState& s = solver.state();
  const EnergyBalance& e = s.energy;
  columns_["time"].push_back(s.time);
  columns_["step"].push_back(static_cast<double>(s.step));
  columns_["time_step"].push_back(s.stable_step);
  // Which integrator took the last step and what the run has cost so far (process CPU, all
  // threads): AUTOMATIC's phases and their cost read off the series.
  columns_["implicit"].push_back(solver.implicit() ? 1.0 : 0.0);
  columns_["newton_iterations"].push_back(static_cast<double>(s.newton_iterations));
  columns_["cpu_time_s"].push_back(static_cast<double>(std::clock()) / CLOCKS_PER_SEC);
  if (solver.automatic()) {
    columns_["energy/slow_kinetic"].push_back(s.slow_kinetic);
    columns_["switches"].push_back(static_cast<double>(s.switches));
    columns_["cost_switches"].push_back(static_cast<double>(s.cost_switches));
  }
  // Where the step comes from: the dt last used (growth limit and contact included), the element
  // that bounds it, the factor the calibration applies to the element bound, and the factor the
  // Lanczos step alone (2 / omega_max) would allow at the last calibration.
  columns_["time_step_source/last"].push_back(s.last_step);
  columns_["time_step_source/critical_element"].push_back(static_cast<double>(s.critical_element));
  columns_["time_step_source/calibration"].push_back(s.step_calibration);
  columns_["time_step_source/lanczos_over_element"].push_back(
      s.element_step_at_calibration > 0 ? s.calibrated_step / s.element_step_at_calibration : 0.0);
  columns_["transvalvular_pressure_Pa"].push_back(pressure_Pa);
  columns_["energy/kinetic"].push_back(e.kinetic);
  columns_["energy/internal_work"].push_back(e.internal_work);
  columns_["energy/strain_energy"].push_back(e.strain_energy);
  columns_["energy/external_work"].push_back(e.external_work);
  columns_["energy/damping_work"].push_back(e.damping_work);
  columns_["energy/contact_work"].push_back(e.contact_work);
  if (s.tie_force.cols() > 0) {  // coaptation tie: work done against it, stored now, state
    columns_["energy/tie_work"].push_back(e.tie_work);
    columns_["energy/tie_energy"].push_back(e.tie_energy);
    columns_["tie/tied_groups"].push_back(static_cast<double>(
        std::count(s.tie.tied.begin(), s.tie.tied.end(), std::uint8_t{1})));
    columns_["tie/releases"].push_back(static_cast<double>(s.tie.releases));
    columns_["tie/peak_force"].push_back(s.tie.peak_force);
  }
  columns_["energy/interface_work"].push_back(e.interface_work);
  if (s.hourglass_force.cols() > 0) {  // bricks: bending lives in the hourglass modes
    columns_["energy/hourglass_work"].push_back(e.hourglass_work);
    columns_["energy/hourglass_energy"].push_back(e.hourglass_energy);
  }
  columns_["energy/numerical_dissipation"].push_back(e.numerical_dissipation);
  columns_["energy/load_step_dissipation"].push_back(e.load_step_dissipation);
  columns_["energy/balance"].push_back(e.balance());
  columns_["energy/relative_balance_error"].push_back(e.relative_balance_error());
  for (std::size_t m = 0; m < monitors_.size(); ++m) {
    double mean_radius = 0.0;
    for (const std::int64_t n : monitors_[m].second) {
      const Eigen::Vector3d x = s.position.col(n);
      monitor_positions_[m].insert(monitor_positions_[m].end(), x.data(), x.data() + 3);
      mean_radius += std::hypot(x.x(), x.y());
    }
    if (!monitors_[m].second.empty()) mean_radius /= static_cast<double>(monitors_[m].second.size());
    columns_["monitor/" + monitors_[m].first + "/mean_radial_position"].push_back(mean_radius);
  }
}

void SeriesWriter::add_snapshot_peaks(double time, double peak_stress, double peak_log_strain) {
  snapshot_time_.push_back(time);
  peak_stress_.push_back(peak_stress);
  peak_strain_.push_back(peak_log_strain);
}

void SeriesWriter::flush() const {
  const auto path = dir_ / (stem_ + ".h5");
  const auto tmp = dir_ / (stem_ + ".h5.tmp");
  {
    H5Handle file(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
    if (!file.valid()) throw std::runtime_error(tmp.string() + ": cannot create output file");
    for (const auto& [name, values] : columns_) {
      write_array(file.get(), "/" + name, values.data(), values.size(), 0);
    }
    for (std::size_t m = 0; m < monitors_.size(); ++m) {
      const hsize_t k = monitors_[m].second.size();
      const hsize_t samples = k == 0 ? 0 : monitor_positions_[m].size() / (3 * k);
      const hsize_t dims[3] = {samples, k, 3};
      H5Handle space(H5Screate_simple(3, dims, nullptr), H5Sclose);
      H5Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
      H5Pset_create_intermediate_group(lcpl.get(), 1);
      const std::string name = "/monitor/" + monitors_[m].first + "/position";
      H5Handle ds(H5Dcreate2(file.get(), name.c_str(), H5T_NATIVE_DOUBLE, space.get(), lcpl.get(), H5P_DEFAULT,
                             H5P_DEFAULT), H5Dclose);
      if (samples > 0) H5Dwrite(ds.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, monitor_positions_[m].data());
    }
    write_array(file.get(), "/snapshots/time", snapshot_time_.data(), snapshot_time_.size(), 0);
    write_array(file.get(), "/snapshots/peak_max_principal_stress", peak_stress_.data(), peak_stress_.size(), 0);
    write_array(file.get(), "/snapshots/peak_max_principal_log_strain", peak_strain_.data(), peak_strain_.size(), 0);
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace valvefsi::solid
