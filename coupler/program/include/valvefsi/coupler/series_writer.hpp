#pragma once
// An appendable table in HDF5: one dataset per column (n_rows x width, or n_rows for width 1),
// chunked and unlimited in rows, with a "unit" attribute. Rows are buffered and written every
// `flush_rows` rows and flushed to disk, so a run that crashes leaves a readable file holding
// everything but the last few rows.

#include <hdf5.h>

#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace valvefsi::coupler {

struct SeriesColumn {
  std::string name;   // dataset name, e.g. "force_fluid"
  int width = 1;      // values per row, e.g. 3 for a vector
  std::string unit;   // e.g. "N"
  std::string description;
};

class SeriesWriter {
 public:
  // Creates (truncates) `path`. Throws std::runtime_error naming the file on failure.
  SeriesWriter(const std::filesystem::path& path, std::vector<SeriesColumn> columns, int flush_rows);
  ~SeriesWriter();
  SeriesWriter(const SeriesWriter&) = delete;
  SeriesWriter& operator=(const SeriesWriter&) = delete;

  // `row` holds every column's values in order (sum of widths). Throws std::invalid_argument
  // on a wrong length.
  void append(std::span<const double> row);
  // Writes buffered rows and flushes the file.
  void flush();
  [[nodiscard]] long long rows_written() const { return rows_on_disk_ + static_cast<long long>(buffered_rows_); }

 private:
  std::filesystem::path path_;
  std::vector<SeriesColumn> columns_;
  int row_width_ = 0;
  int flush_rows_;
  hid_t file_ = -1;
  std::vector<hid_t> datasets_;
  std::vector<double> buffer_;  // row-major, buffered_rows_ x row_width_
  std::size_t buffered_rows_ = 0;
  long long rows_on_disk_ = 0;
};

}  // namespace valvefsi::coupler
