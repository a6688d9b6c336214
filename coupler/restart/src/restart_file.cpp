#include "valvefsi/coupling/restart_file.hpp"

#include <fmt/format.h>
#include <hdf5.h>

#include <cstring>
#include <stdexcept>
#include <system_error>

namespace valvefsi::coupling {

namespace {

constexpr int kReal = 0;
constexpr int kInteger = 1;

std::string dataset_name(std::string_view name) {
  // Stored flat: HDF5 would read '/' as groups.
  std::string flat(name);
  for (char& c : flat)
    if (c == '/') c = '|';
  return flat;
}

template <typename T>
std::vector<T> as_vector(const std::vector<unsigned char>& bytes, std::size_t count) {
  std::vector<T> values(count);
  if (count > 0) std::memcpy(values.data(), bytes.data(), count * sizeof(T));
  return values;
}

}  // namespace

std::filesystem::path restart_file_path(const std::filesystem::path& directory,
                                        std::string_view participant) {
  return directory / fmt::format("{}.restart.h5", participant);
}

RestartWriter::RestartWriter(std::filesystem::path file) : file_(std::move(file)) {
  partial_ = file_;
  partial_ += ".partial";
  if (file_.has_parent_path()) std::filesystem::create_directories(file_.parent_path());
  handle_ = H5Fcreate(partial_.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (handle_ < 0)
    throw std::runtime_error(fmt::format("{}: cannot create the restart file", partial_.string()));
}

RestartWriter::~RestartWriter() {
  if (committed_) return;
  if (handle_ >= 0) H5Fclose(static_cast<hid_t>(handle_));
  std::error_code ignored;
  std::filesystem::remove(partial_, ignored);
}

void RestartWriter::write(std::string_view name, const void* data, std::size_t count, bool integer,
                          int element_bytes) {
  if (committed_)
    throw std::logic_error(fmt::format("{}: put('{}') after commit()", file_.string(), name));
  const std::string flat = dataset_name(name);
  const hid_t file = static_cast<hid_t>(handle_);
  if (H5Lexists(file, flat.c_str(), H5P_DEFAULT) > 0)
    throw std::logic_error(fmt::format("{}: entry '{}' written twice", file_.string(), name));
  const hid_t type =
      integer ? H5T_NATIVE_INT64 : (element_bytes == 4 ? H5T_NATIVE_FLOAT : H5T_NATIVE_DOUBLE);
  const hsize_t size = count;
  const hid_t space = H5Screate_simple(1, &size, nullptr);
  const hid_t dataset =
      H5Dcreate2(file, flat.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  const herr_t status = dataset < 0 || count == 0
                            ? (dataset < 0 ? -1 : 0)
                            : H5Dwrite(dataset, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
  if (dataset >= 0) H5Dclose(dataset);
  H5Sclose(space);
  if (status < 0)
    throw std::runtime_error(fmt::format("{}: cannot write entry '{}'", partial_.string(), name));
}

void RestartWriter::put(std::string_view name, std::span<const double> values) {
  write(name, values.data(), values.size(), false, 8);
}
void RestartWriter::put(std::string_view name, std::span<const float> values) {
  write(name, values.data(), values.size(), false, 4);
}
void RestartWriter::put(std::string_view name, std::span<const std::int64_t> values) {
  write(name, values.data(), values.size(), true, 8);
}
void RestartWriter::put(std::string_view name, const Eigen::Matrix3Xd& columns) {
  write(name, columns.data(), static_cast<std::size_t>(columns.size()), false, 8);
}

void RestartWriter::commit() {
  if (committed_) return;
  if (H5Fclose(static_cast<hid_t>(handle_)) < 0)
    throw std::runtime_error(fmt::format("{}: cannot close the restart file", partial_.string()));
  handle_ = -1;
  std::filesystem::rename(partial_, file_);
  committed_ = true;
}

RestartReader::RestartReader(std::filesystem::path file) : file_(std::move(file)) {
  if (!std::filesystem::exists(file_))
    throw std::runtime_error(fmt::format("{}: no such restart file", file_.string()));
  handle_ = H5Fopen(file_.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (handle_ < 0)
    throw std::runtime_error(fmt::format("{}: not a readable HDF5 restart file", file_.string()));
}

RestartReader::~RestartReader() {
  if (handle_ >= 0) H5Fclose(static_cast<hid_t>(handle_));
}

bool RestartReader::has(std::string_view name) const {
  return H5Lexists(static_cast<hid_t>(handle_), dataset_name(name).c_str(), H5P_DEFAULT) > 0;
}

std::vector<unsigned char> RestartReader::read(std::string_view name, int kind, int element_bytes,
                                               std::ptrdiff_t expected_size,
                                               std::size_t& count) const {
  if (!has(name))
    throw std::runtime_error(
        fmt::format("{}: the restart file has no entry '{}'", file_.string(), name));
  const hid_t dataset =
      H5Dopen2(static_cast<hid_t>(handle_), dataset_name(name).c_str(), H5P_DEFAULT);
  const hid_t stored_type = H5Dget_type(dataset);
  const bool is_integer = H5Tget_class(stored_type) == H5T_INTEGER;
  const auto stored_bytes = static_cast<int>(H5Tget_size(stored_type));
  H5Tclose(stored_type);
  const hid_t space = H5Dget_space(dataset);
  hsize_t size = 0;
  const int rank = H5Sget_simple_extent_ndims(space);
  if (rank == 1) H5Sget_simple_extent_dims(space, &size, nullptr);
  H5Sclose(space);
  const char* wanted =
      kind == kInteger ? "64-bit integers" : (element_bytes == 4 ? "floats" : "doubles");
  if (rank != 1 || is_integer != (kind == kInteger) || stored_bytes != element_bytes) {
    H5Dclose(dataset);
    throw std::runtime_error(
        fmt::format("{}: entry '{}' is not a list of {}", file_.string(), name, wanted));
  }
  if (expected_size >= 0 && size != static_cast<hsize_t>(expected_size)) {
    H5Dclose(dataset);
    throw std::runtime_error(
        fmt::format("{}: entry '{}' has {} values; this run needs {} (a restart of another case?)",
                    file_.string(), name, size, expected_size));
  }
  count = static_cast<std::size_t>(size);
  std::vector<unsigned char> bytes(count * static_cast<std::size_t>(element_bytes));
  const hid_t type = kind == kInteger ? H5T_NATIVE_INT64
                                      : (element_bytes == 4 ? H5T_NATIVE_FLOAT : H5T_NATIVE_DOUBLE);
  const herr_t status =
      count == 0 ? 0 : H5Dread(dataset, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, bytes.data());
  H5Dclose(dataset);
  if (status < 0)
    throw std::runtime_error(fmt::format("{}: cannot read entry '{}'", file_.string(), name));
  return bytes;
}

std::vector<double> RestartReader::doubles(std::string_view name,
                                           std::ptrdiff_t expected_size) const {
  std::size_t count = 0;
  const auto bytes = read(name, kReal, 8, expected_size, count);
  return as_vector<double>(bytes, count);
}

std::vector<float> RestartReader::floats(std::string_view name,
                                         std::ptrdiff_t expected_size) const {
  std::size_t count = 0;
  const auto bytes = read(name, kReal, 4, expected_size, count);
  return as_vector<float>(bytes, count);
}

std::vector<std::int64_t> RestartReader::integers(std::string_view name,
                                                  std::ptrdiff_t expected_size) const {
  std::size_t count = 0;
  const auto bytes = read(name, kInteger, 8, expected_size, count);
  return as_vector<std::int64_t>(bytes, count);
}

Eigen::Matrix3Xd RestartReader::matrix3x(std::string_view name,
                                         Eigen::Index expected_columns) const {
  const auto values = doubles(name, expected_columns < 0 ? -1 : 3 * expected_columns);
  if (values.size() % 3 != 0)
    throw std::runtime_error(fmt::format("{}: entry '{}' has {} values, not 3 per point",
                                         file_.string(), name, values.size()));
  return Eigen::Map<const Eigen::Matrix3Xd>(values.data(), 3,
                                            static_cast<Eigen::Index>(values.size() / 3));
}

}  // namespace valvefsi::coupling
