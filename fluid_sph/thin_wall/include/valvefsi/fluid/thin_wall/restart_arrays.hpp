#pragma once
// The thin-wall models' restart state as the contract's named arrays of doubles
// (ImmersedSurfaceModel::restart_state): a writer that flattens scalars, fixed-size vectors
// and lists of lists, and a reader that finds an array by name and checks its length, naming
// the array (and what was expected) when it is missing or of the wrong size. Doubles and
// integers below 2^53 come back exactly, so a restored model continues bit for bit.
#include <fmt/format.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "valvefsi/fluid/immersed_surface.hpp"

namespace valvefsi::fluid::thin_wall {

class RestartWriter {
 public:
  template <class T>
  void scalars(const std::string& name, const std::vector<T>& values) {
    std::vector<double> out(values.size());
    for (std::size_t k = 0; k < values.size(); ++k) out[k] = static_cast<double>(values[k]);
    arrays_.push_back({name, std::move(out)});
  }
  template <std::size_t N>
  void vectors(const std::string& name, const std::vector<std::array<double, N>>& values) {
    std::vector<double> out;
    out.reserve(N * values.size());
    for (const auto& v : values) out.insert(out.end(), v.begin(), v.end());
    arrays_.push_back({name, std::move(out)});
  }
  // A list of index lists: "<name>.offsets" (size + 1 entries) and "<name>.values".
  void lists(const std::string& name, const std::vector<std::vector<std::uint32_t>>& lists) {
    std::vector<double> offsets{0.0}, values;
    for (const auto& l : lists) {
      for (const auto v : l) values.push_back(v);
      offsets.push_back(static_cast<double>(values.size()));
    }
    arrays_.push_back({name + ".offsets", std::move(offsets)});
    arrays_.push_back({name + ".values", std::move(values)});
  }
  std::vector<NamedArray> take() { return std::move(arrays_); }

 private:
  std::vector<NamedArray> arrays_;
};

class RestartReader {
 public:
  // `owner` names the model in errors (e.g. "thin wall 3D restart state").
  RestartReader(std::span<const NamedArray> arrays, std::string owner) : arrays_(arrays), owner_(std::move(owner)) {}

  // The array `name`; `entries` > 0: it must hold exactly entries x width values; 0: any whole
  // number of entries of `width` values. Returns the number of entries.
  const std::vector<double>& find(const std::string& name, std::size_t width, std::size_t entries, std::size_t* count = nullptr) const {
    for (const auto& a : arrays_)
      if (a.name == name) {
        const std::size_t n = a.values.size();
        if (width == 0 || n % width != 0 || (entries > 0 && n != width * entries))
          throw std::runtime_error(fmt::format("{}: array '{}' has {} values: allowed {}", owner_, name, n,
                                               entries > 0 ? fmt::format("{} ({} x {})", width * entries, entries, width)
                                                           : fmt::format("a multiple of {}", width)));
        if (count) *count = n / width;
        return a.values;
      }
    throw std::runtime_error(fmt::format("{}: array '{}' is missing", owner_, name));
  }
  bool has(const std::string& name) const {
    for (const auto& a : arrays_)
      if (a.name == name) return true;
    return false;
  }
  template <class T>
  std::vector<T> scalars(const std::string& name, std::size_t entries = 0) const {
    const auto& v = find(name, 1, entries);
    std::vector<T> out(v.size());
    for (std::size_t k = 0; k < v.size(); ++k) out[k] = static_cast<T>(v[k]);
    return out;
  }
  template <std::size_t N>
  std::vector<std::array<double, N>> vectors(const std::string& name, std::size_t entries = 0) const {
    std::size_t count = 0;
    const auto& v = find(name, N, entries, &count);
    std::vector<std::array<double, N>> out(count);
    for (std::size_t k = 0; k < count; ++k)
      for (std::size_t d = 0; d < N; ++d) out[k][d] = v[N * k + d];
    return out;
  }
  std::vector<std::vector<std::uint32_t>> lists(const std::string& name, std::size_t entries = 0) const {
    const auto offsets = scalars<std::size_t>(name + ".offsets", entries > 0 ? entries + 1 : 0);
    const auto& values = find(name + ".values", 1, 0);
    if (offsets.empty() || offsets.front() != 0 || offsets.back() != values.size())
      throw std::runtime_error(fmt::format("{}: arrays '{}.offsets' and '{}.values' do not match ({} offsets ending at {}, {} values)",
                                           owner_, name, name, offsets.size(), offsets.empty() ? 0 : offsets.back(), values.size()));
    std::vector<std::vector<std::uint32_t>> out(offsets.size() - 1);
    for (std::size_t k = 0; k + 1 < offsets.size(); ++k) {
      if (offsets[k + 1] < offsets[k])
        throw std::runtime_error(fmt::format("{}: array '{}.offsets' decreases at entry {}", owner_, name, k + 1));
      for (std::size_t j = offsets[k]; j < offsets[k + 1]; ++j) out[k].push_back(static_cast<std::uint32_t>(values[j]));
    }
    return out;
  }
  const std::string& owner() const { return owner_; }

 private:
  std::span<const NamedArray> arrays_;
  std::string owner_;
};

}  // namespace valvefsi::fluid::thin_wall
