#include "valvefsi/coupler/series_writer.hpp"

#include <fmt/format.h>

#include <stdexcept>

namespace valvefsi::coupler {

namespace {

void check(herr_t status, const std::filesystem::path& path, const char* what) {
  if (status < 0) throw std::runtime_error(fmt::format("{}: HDF5 failed to {}", path.string(), what));
}

void write_string_attribute(hid_t object, const char* name, const std::string& value) {
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, value.empty() ? 1 : value.size());
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t attribute = H5Acreate2(object, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(attribute, type, value.empty() ? "" : value.c_str());
  H5Aclose(attribute);
  H5Sclose(space);
  H5Tclose(type);
}

}  // namespace

SeriesWriter::SeriesWriter(const std::filesystem::path& path, std::vector<SeriesColumn> columns, int flush_rows)
    : path_(path), columns_(std::move(columns)), flush_rows_(flush_rows < 1 ? 1 : flush_rows) {
  if (path_.has_parent_path()) std::filesystem::create_directories(path_.parent_path());
  file_ = H5Fcreate(path_.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file_ < 0) throw std::runtime_error(fmt::format("{}: cannot create the HDF5 series file", path_.string()));
  const hsize_t chunk_rows = static_cast<hsize_t>(std::max(flush_rows_, 64));
  for (const auto& column : columns_) {
    const int rank = column.width == 1 ? 1 : 2;
    const hsize_t initial[2] = {0, static_cast<hsize_t>(column.width)};
    const hsize_t maximum[2] = {H5S_UNLIMITED, static_cast<hsize_t>(column.width)};
    const hsize_t chunk[2] = {chunk_rows, static_cast<hsize_t>(column.width)};
    const hid_t space = H5Screate_simple(rank, initial, maximum);
    const hid_t properties = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_chunk(properties, rank, chunk);
    const hid_t dataset =
        H5Dcreate2(file_, column.name.c_str(), H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, properties, H5P_DEFAULT);
    H5Pclose(properties);
    H5Sclose(space);
    if (dataset < 0) throw std::runtime_error(fmt::format("{}: cannot create dataset '{}'", path_.string(), column.name));
    write_string_attribute(dataset, "unit", column.unit);
    write_string_attribute(dataset, "description", column.description);
    datasets_.push_back(dataset);
    row_width_ += column.width;
  }
  check(H5Fflush(file_, H5F_SCOPE_GLOBAL), path_, "flush");
}

SeriesWriter::~SeriesWriter() {
  try {
    flush();
  } catch (...) {
    // Destructors must not throw; the rows already on disk stay readable.
  }
  for (const hid_t dataset : datasets_) H5Dclose(dataset);
  if (file_ >= 0) H5Fclose(file_);
}

void SeriesWriter::append(std::span<const double> row) {
  if (row.size() != static_cast<std::size_t>(row_width_)) {
    throw std::invalid_argument(fmt::format("{}: a series row needs {} values, got {}", path_.string(), row_width_, row.size()));
  }
  buffer_.insert(buffer_.end(), row.begin(), row.end());
  if (++buffered_rows_ >= static_cast<std::size_t>(flush_rows_)) flush();
}

void SeriesWriter::flush() {
  if (buffered_rows_ == 0 || file_ < 0) return;
  const hsize_t new_rows = buffered_rows_;
  int offset = 0;
  std::vector<double> block;
  for (std::size_t c = 0; c < columns_.size(); ++c) {
    const auto width = static_cast<hsize_t>(columns_[c].width);
    const int rank = width == 1 ? 1 : 2;
    block.resize(new_rows * width);
    for (hsize_t r = 0; r < new_rows; ++r) {
      for (hsize_t k = 0; k < width; ++k) block[r * width + k] = buffer_[r * row_width_ + offset + k];
    }
    const hsize_t extent[2] = {static_cast<hsize_t>(rows_on_disk_) + new_rows, width};
    check(H5Dset_extent(datasets_[c], extent), path_, "extend a dataset");
    const hid_t file_space = H5Dget_space(datasets_[c]);
    const hsize_t start[2] = {static_cast<hsize_t>(rows_on_disk_), 0};
    const hsize_t count[2] = {new_rows, width};
    H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start, nullptr, count, nullptr);
    const hid_t memory_space = H5Screate_simple(rank, count, nullptr);
    const herr_t status = H5Dwrite(datasets_[c], H5T_NATIVE_DOUBLE, memory_space, file_space, H5P_DEFAULT, block.data());
    H5Sclose(memory_space);
    H5Sclose(file_space);
    check(status, path_, "write rows");
    offset += columns_[c].width;
  }
  rows_on_disk_ += static_cast<long long>(new_rows);
  buffered_rows_ = 0;
  buffer_.clear();
  check(H5Fflush(file_, H5F_SCOPE_GLOBAL), path_, "flush");
}

}  // namespace valvefsi::coupler
