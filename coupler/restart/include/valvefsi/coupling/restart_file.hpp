#pragma once
// Restart files: a program's whole state at a restart point, as named arrays of doubles and
// 64-bit integers in one HDF5 file (h5dump shows what is inside). The writer builds the file
// under a temporary name and renames it on commit(), so an interrupted write never leaves a
// half file under the real name. docs/coupling.md, "Restarts".
#include <Eigen/Core>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace valvefsi::coupling {

// <directory>/<participant>.restart.h5 ("fluid", "solid", "coupler").
std::filesystem::path restart_file_path(const std::filesystem::path& directory,
                                        std::string_view participant);

class RestartWriter {
 public:
  // Creates <file>.partial; throws std::runtime_error naming the file if it cannot.
  explicit RestartWriter(std::filesystem::path file);
  ~RestartWriter();  // without commit(): removes the partial file
  RestartWriter(const RestartWriter&) = delete;
  RestartWriter& operator=(const RestartWriter&) = delete;

  // Each name once; names may contain '/' only as a plain character (stored flat).
  void put(std::string_view name, std::span<const double> values);
  void put(std::string_view name, std::span<const float> values);
  void put(std::string_view name, std::span<const std::int64_t> values);
  void put(std::string_view name, double value) { put(name, std::span<const double>(&value, 1)); }
  void put_integer(std::string_view name, std::int64_t value) {
    put(name, std::span<const std::int64_t>(&value, 1));
  }
  void put(std::string_view name,
           const Eigen::Matrix3Xd& columns);  // stored as 3 x n (column-major)
  // Closes the file and renames it to its real name.
  void commit();

 private:
  void write(std::string_view name, const void* data, std::size_t count, bool integer,
             int element_bytes);
  std::filesystem::path file_, partial_;
  std::int64_t handle_ = -1;
  bool committed_ = false;
};

class RestartReader {
 public:
  // Throws std::runtime_error naming the file when it is missing or not a restart file.
  explicit RestartReader(std::filesystem::path file);
  ~RestartReader();
  RestartReader(const RestartReader&) = delete;
  RestartReader& operator=(const RestartReader&) = delete;

  bool has(std::string_view name) const;
  // Each throws std::runtime_error naming the file and the entry when it is missing, of the
  // wrong kind, or (where a size is given) of the wrong size.
  std::vector<double> doubles(std::string_view name, std::ptrdiff_t expected_size = -1) const;
  std::vector<float> floats(std::string_view name, std::ptrdiff_t expected_size = -1) const;
  std::vector<std::int64_t> integers(std::string_view name,
                                     std::ptrdiff_t expected_size = -1) const;
  double scalar(std::string_view name) const { return doubles(name, 1)[0]; }
  std::int64_t integer(std::string_view name) const { return integers(name, 1)[0]; }
  Eigen::Matrix3Xd matrix3x(std::string_view name, Eigen::Index expected_columns = -1) const;
  const std::filesystem::path& file() const { return file_; }

 private:
  std::vector<unsigned char> read(std::string_view name, int kind, int element_bytes,
                                  std::ptrdiff_t expected_size, std::size_t& count) const;
  std::filesystem::path file_;
  std::int64_t handle_ = -1;
};

}  // namespace valvefsi::coupling
