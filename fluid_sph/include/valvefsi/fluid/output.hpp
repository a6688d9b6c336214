#pragma once
// Output of a fluid run: particle snapshots in HDF5 with an XDMF index that ParaView opens
// (fluid_particles.xmf), and probe time series in HDF5 (fluid_probes.h5).
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "valvefsi/fluid/fluid_solver.hpp"

namespace valvefsi::fluid {

// Each write adds group /snapshot_NNNNNN (attribute time; datasets position and velocity
// (n x 3, z = 0 in 2D), pressure (gauge, Pa), density (kg/m^3), kind (0 fluid, 1 wall,
// 2 lost), id) to fluid_particles.h5, and rewrites the XDMF time collection.
template <int D>
class SnapshotWriter {
 public:
  // `writes`: false on the ranks other than 0 of a run split over MPI ranks (they only send).
  explicit SnapshotWriter(const std::filesystem::path& directory, bool writes = true);
  // Collective when the run is split: the ranks' own (and lost) particles are gathered on rank 0.
  void write(const FluidSolver<D>& solver);
  std::size_t count() const { return entries_.size(); }

 private:
  struct Entry {
    double time;
    std::size_t particles;
  };
  void write_xdmf() const;
  std::filesystem::path directory_;
  bool writes_ = true;
  std::vector<Entry> entries_;
};

// Named columns of one or more components sampled over time; flush() rewrites the file with
// dataset /time and one dataset per column (samples x components), e.g. /pressure/upstream.
class SeriesWriter {
 public:
  explicit SeriesWriter(std::filesystem::path file) : file_(std::move(file)) {}
  // Columns must all be declared before the first append.
  void add_column(const std::string& path, int components = 1);
  void append(double time, const std::vector<double>& values);  // all columns' components, in order
  // A number about the whole series, written as an attribute of the file's root.
  void set_attribute(const std::string& name, double value);
  void flush() const;
  std::size_t samples() const { return time_.size(); }

 private:
  struct Column {
    std::string path;
    int components;
    std::vector<double> data;
  };
  std::filesystem::path file_;
  std::vector<double> time_;
  std::vector<Column> columns_;
  std::vector<std::pair<std::string, double>> attributes_;
};

}  // namespace valvefsi::fluid
