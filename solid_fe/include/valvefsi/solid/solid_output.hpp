#pragma once
// Output of a solid run: field snapshots (HDF5 + XDMF, opens in ParaView) and time series
// (energies, monitored nodes, stable step) in HDF5. Layout in docs/solid_fe.md.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "valvefsi/solid/hdf5_handle.hpp"
#include "valvefsi/solid/mesh.hpp"
#include "valvefsi/solid/explicit_solver.hpp"

namespace valvefsi::solid {

// The file-name suffix of a run continued from a restart point (docs/solid_fe.md, "Restarts"):
// "" when `dir` holds no solid output yet (a new output folder: the usual names), otherwise
// "_t_<restart time, 9 decimals>", so continuing in the first run's own folder never overwrites
// its files.
std::string restarted_output_suffix(const std::filesystem::path& dir, double restart_time);

// <dir>/solid_fields<suffix>.h5 and .xdmf: the mesh's triangles (shells) or hexahedra (bricks),
// node fields and one value per element.
class FieldWriter {
 public:
  FieldWriter(const std::filesystem::path& dir, const Mesh& mesh, ElementFamily family = ElementFamily::shell,
              const std::string& suffix = "");
  // Writes positions, displacement, velocity and the element fields of the solver's state.
  void write(const ExplicitSolver& solver, double& peak_stress, double& peak_log_strain);
  int count() const { return static_cast<int>(times_.size()); }

 private:
  void write_xdmf() const;

  std::filesystem::path dir_;
  std::string stem_;
  H5Handle file_;
  ElementFamily family_;
  std::int64_t num_nodes_, num_elements_;
  std::vector<double> times_;
};

// <dir>/solid_series<suffix>.h5, rewritten whole at each flush (small; safe to read during a run).
class SeriesWriter {
 public:
  SeriesWriter(std::filesystem::path dir, std::vector<std::pair<std::string, std::vector<std::int64_t>>> monitors,
               const std::string& suffix = "");
  void sample(const ExplicitSolver& solver, double pressure_Pa);
  void add_snapshot_peaks(double time, double peak_stress, double peak_log_strain);
  void flush() const;

 private:
  std::filesystem::path dir_;
  std::string stem_;
  std::vector<std::pair<std::string, std::vector<std::int64_t>>> monitors_;
  std::map<std::string, std::vector<double>> columns_;
  std::vector<std::vector<double>> monitor_positions_;  // per set: samples x nodes x 3, flattened
  std::vector<double> snapshot_time_, peak_stress_, peak_strain_;
};

}  // namespace valvefsi::solid
