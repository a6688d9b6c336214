// FluidSolver's restart state: everything a step reads, as named arrays of doubles (floats,
// small integers and kinds are exact in a double), so a run restarted from a file continues
// bit for bit. Nothing is re-sorted or re-evaluated on load (as for the in-memory checkpoint).
#include <fmt/format.h>

#include <map>
#include <stdexcept>
#include <string>
#include <string_view>

#include "valvefsi/fluid/fluid_solver.hpp"

namespace valvefsi::fluid {
namespace {

constexpr std::string_view kSurfacePrefix = "surface/";

template <class T>
NamedArray named(std::string name, const std::vector<T>& values) {
  NamedArray a{std::move(name), {}};
  a.values.reserve(values.size());
  for (const T& v : values) a.values.push_back(static_cast<double>(v));
  return a;
}

NamedArray scalar(std::string name, double value) { return NamedArray{std::move(name), {value}}; }

// The arrays by name; each lookup checks presence and (where given) size.
class Lookup {
 public:
  explicit Lookup(std::span<const NamedArray> arrays) {
    for (const auto& a : arrays) by_name_[a.name] = &a.values;
  }
  const std::vector<double>& get(const std::string& name, std::ptrdiff_t expected = -1) const {
    const auto it = by_name_.find(name);
    if (it == by_name_.end()) throw std::runtime_error("fluid restart state: no array '" + name + "'");
    if (expected >= 0 && it->second->size() != static_cast<std::size_t>(expected))
      throw std::runtime_error(fmt::format("fluid restart state: array '{}' has {} values, expected {}", name,
                                           it->second->size(), expected));
    return *it->second;
  }
  double scalar(const std::string& name) const { return get(name, 1)[0]; }
  bool has(const std::string& name) const { return by_name_.contains(name); }
  template <class T>
  void into(const std::string& name, std::vector<T>& out, std::ptrdiff_t expected = -1) const {
    const auto& values = get(name, expected);
    out.resize(values.size());
    for (std::size_t i = 0; i < values.size(); ++i) out[i] = static_cast<T>(values[i]);
  }

 private:
  std::map<std::string, const std::vector<double>*, std::less<>> by_name_;
};

template <class T>
NamedArray named_kinds(std::string name, const std::vector<T>& kinds) {
  NamedArray a{std::move(name), {}};
  a.values.reserve(kinds.size());
  for (const T k : kinds) a.values.push_back(static_cast<double>(static_cast<int>(k)));
  return a;
}

}  // namespace

template <int D>
std::optional<std::vector<NamedArray>> FluidSolver<D>::restart_state() const {
  std::optional<std::vector<NamedArray>> surface_state;
  if (surface_) {
    surface_state = surface_->restart_state();
    if (!surface_state) return std::nullopt;
  }
  std::vector<NamedArray> out;
  const auto& p = particles_;
  const std::string axes = "xyz";
  for (int d = 0; d < D; ++d) {
    const std::string a(1, axes[static_cast<std::size_t>(d)]);
    out.push_back(named("particles/position_" + a, p.position[d]));
    out.push_back(named("particles/velocity_" + a, p.velocity[d]));
    out.push_back(named("particles/viscous_velocity_" + a, p.viscous_velocity[d]));
    out.push_back(named("particles/acceleration_" + a, p.acceleration[d]));
    out.push_back(named("particles/local_position_" + a, p.local_position[d]));
    out.push_back(named("particles/kernel_sum_gradient_" + a, p.kernel_sum_gradient[d]));
  }
  out.push_back(named("particles/density_excess", p.density_excess));
  out.push_back(named("particles/density_rate", p.density_rate));
  out.push_back(named("particles/density_rate_previous", p.density_rate_previous));
  out.push_back(named("particles/pressure", p.pressure));
  out.push_back(named_kinds("particles/kind", p.kind));
  out.push_back(named("particles/body", p.body));
  out.push_back(named("particles/id", p.id));
  out.push_back(named("particles/fluid_mask", p.fluid_mask));
  out.push_back(named("particles/inverse_density", p.inverse_density));
  out.push_back(named("particles/near_fluid", p.near_fluid));
  out.push_back(named("particles/near_wall", p.near_wall));
  out.push_back(named("particles/kernel_sum", p.kernel_sum));
  out.push_back(named("grid/cell_starts", grid_.cell_starts()));
  out.push_back(named("near_surface", near_surface_));
  std::vector<double> plate_state;
  for (const auto& plate : plates_) {
    plate_state.push_back(plate.displacement);
    plate_state.push_back(plate.velocity);
    plate_state.push_back(plate.acceleration);
    for (int d = 0; d < D; ++d) plate_state.push_back(plate.fluid_force[d]);
  }
  out.push_back(NamedArray{"plates", std::move(plate_state)});
  std::vector<double> bodies;
  for (const auto& f : body_forces_)
    for (int d = 0; d < D; ++d) bodies.push_back(f[d]);
  out.push_back(NamedArray{"body_forces", bodies});
  bodies.clear();
  for (const auto& a : body_acceleration_)
    for (int d = 0; d < D; ++d) bodies.push_back(a[d]);
  out.push_back(NamedArray{"body_acceleration", std::move(bodies)});
  std::vector<double> force_sum;
  for (const auto& f : surface_force_sum_)
    for (int d = 0; d < D; ++d) force_sum.push_back(f[d]);
  out.push_back(NamedArray{"surface_force_sum", std::move(force_sum)});
  out.push_back(scalar("surface_force_time", surface_force_time_));
  out.push_back(scalar("dimension", D));
  out.push_back(scalar("ranks", slabs_ ? slabs_->size() : 1));
  out.push_back(scalar("rank", slabs_ ? slabs_->rank() : 0));
  out.push_back(scalar("time", time_));
  out.push_back(scalar("dt", dt_));
  out.push_back(scalar("steps", static_cast<double>(steps_)));
  out.push_back(scalar("lost", static_cast<double>(lost_)));
  out.push_back(scalar("lost_density", static_cast<double>(lost_density_)));
  out.push_back(scalar("max_speed", max_speed_));
  out.push_back(scalar("max_acceleration", max_acceleration_));
  out.push_back(scalar("body_forces_requested", body_forces_requested_ ? 1.0 : 0.0));
  out.push_back(scalar("plate_floor_reached", plate_floor_reached_ ? 1.0 : 0.0));
  if (surface_state)
    for (auto& a : *surface_state) out.push_back(NamedArray{std::string(kSurfacePrefix) + a.name, std::move(a.values)});
  return out;
}

template <int D>
void FluidSolver<D>::load_restart_state(std::span<const NamedArray> arrays) {
  const Lookup in(arrays);
  if (in.scalar("dimension") != D)
    throw std::runtime_error(fmt::format("fluid restart state: written by a {}D fluid, this one is {}D", in.scalar("dimension"), D));
  auto& p = particles_;
  const std::string axes = "xyz";
  const auto& kinds = in.get("particles/kind");
  p.kind.resize(kinds.size());
  for (std::size_t i = 0; i < kinds.size(); ++i) p.kind[i] = static_cast<Kind>(static_cast<int>(kinds[i]));
  const auto n = static_cast<std::ptrdiff_t>(p.kind.size());
  for (int d = 0; d < D; ++d) {
    const std::string a(1, axes[static_cast<std::size_t>(d)]);
    in.into("particles/position_" + a, p.position[d], n);
    in.into("particles/velocity_" + a, p.velocity[d], n);
    in.into("particles/viscous_velocity_" + a, p.viscous_velocity[d], n);
    in.into("particles/acceleration_" + a, p.acceleration[d], n);
    in.into("particles/local_position_" + a, p.local_position[d]);
    in.into("particles/kernel_sum_gradient_" + a, p.kernel_sum_gradient[d]);
  }
  in.into("particles/density_excess", p.density_excess, n);
  in.into("particles/density_rate", p.density_rate, n);
  in.into("particles/density_rate_previous", p.density_rate_previous, n);
  in.into("particles/pressure", p.pressure, n);
  in.into("particles/body", p.body, n);
  in.into("particles/id", p.id, n);
  in.into("particles/fluid_mask", p.fluid_mask);
  in.into("particles/inverse_density", p.inverse_density);
  in.into("particles/near_fluid", p.near_fluid);
  in.into("particles/near_wall", p.near_wall);
  in.into("particles/kernel_sum", p.kernel_sum);
  std::vector<std::uint32_t> starts;
  in.into("grid/cell_starts", starts);
  grid_.set_cell_starts(std::move(starts));
  in.into("near_surface", near_surface_);
  const int ranks = slabs_ ? slabs_->size() : 1, rank = slabs_ ? slabs_->rank() : 0;
  if (in.scalar("ranks") != ranks || in.scalar("rank") != rank)
    throw std::runtime_error(fmt::format("fluid restart state: written by rank {} of {}, read by rank {} of {} (restart with "
                                         "the same number of ranks)", in.scalar("rank"), in.scalar("ranks"), rank, ranks));
  update_owned_range();
  const auto& plate_state = in.get("plates", static_cast<std::ptrdiff_t>(plates_.size() * (3 + D)));
  for (std::size_t k = 0; k < plates_.size(); ++k) {
    const double* s = plate_state.data() + k * (3 + D);
    plates_[k].displacement = s[0];
    plates_[k].velocity = s[1];
    plates_[k].acceleration = s[2];
    for (int d = 0; d < D; ++d) plates_[k].fluid_force[d] = s[3 + d];
  }
  const auto bodies = static_cast<std::ptrdiff_t>((plates_.size() + 1) * D);
  const auto& forces = in.get("body_forces", bodies);
  const auto& accelerations = in.get("body_acceleration", bodies);
  for (std::size_t k = 0; k <= plates_.size(); ++k)
    for (int d = 0; d < D; ++d) {
      body_forces_[k][d] = forces[k * D + static_cast<std::size_t>(d)];
      body_acceleration_[k][d] = accelerations[k * D + static_cast<std::size_t>(d)];
    }
  const auto& force_sum = in.get("surface_force_sum");
  if (force_sum.size() % D != 0) throw std::runtime_error("fluid restart state: surface_force_sum is not a list of vectors");
  surface_force_sum_.assign(force_sum.size() / D, Vec<D>{});
  for (std::size_t j = 0; j < surface_force_sum_.size(); ++j)
    for (int d = 0; d < D; ++d) surface_force_sum_[j][d] = force_sum[j * D + static_cast<std::size_t>(d)];
  surface_force_time_ = in.scalar("surface_force_time");
  time_ = in.scalar("time");
  dt_ = in.scalar("dt");
  steps_ = static_cast<long>(in.scalar("steps"));
  lost_ = static_cast<std::size_t>(in.scalar("lost"));
  lost_density_ = static_cast<std::size_t>(in.scalar("lost_density"));
  max_speed_ = static_cast<float>(in.scalar("max_speed"));
  max_acceleration_ = static_cast<float>(in.scalar("max_acceleration"));
  body_forces_requested_ = in.scalar("body_forces_requested") != 0.0;
  if (in.has("plate_floor_reached")) {
    plate_floor_reached_ = in.scalar("plate_floor_reached") != 0.0;
  } else {
    // Files written before the flag existed: the drives depend on time only, so replay them
    // at the file's step from 0 to its time.
    plate_floor_reached_ = !settings_.plate_floor_once_reached;
    const double sample = dt_ > 0 ? dt_ : 1e-6;
    for (double t = 0.0; t < time_ && !plate_floor_reached_; t += sample) note_plate_floor(t);
    note_plate_floor(time_);
  }
  checkpoint_.reset();

  std::vector<NamedArray> surface_arrays;
  for (const auto& a : arrays)
    if (a.name.starts_with(kSurfacePrefix)) surface_arrays.push_back(NamedArray{a.name.substr(kSurfacePrefix.size()), a.values});
  if (surface_) {
    surface_->load_restart_state(surface_arrays);
  } else if (!surface_arrays.empty()) {
    throw std::runtime_error("fluid restart state: written with an immersed surface, but this run has none");
  }
}

template std::optional<std::vector<NamedArray>> FluidSolver<2>::restart_state() const;
template std::optional<std::vector<NamedArray>> FluidSolver<3>::restart_state() const;
template void FluidSolver<2>::load_restart_state(std::span<const NamedArray>);
template void FluidSolver<3>::load_restart_state(std::span<const NamedArray>);

}  // namespace valvefsi::fluid
