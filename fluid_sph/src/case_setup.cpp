#include "valvefsi/fluid/case_setup.hpp"

#include <fmt/format.h>

#include <cmath>
#include <memory>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/case/pressure_waveform.hpp"
#include "valvefsi/fluid/mirror_group.hpp"

namespace valvefsi::fluid {
namespace {

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& field, const std::string& message) const {
    throw CaseError(fmt::format("{}: field 'fluid.{}' {}", file_, field, message));
  }

  template <int D, class Repeated>
  Vec<D> vec(const Repeated& values, const std::string& field) const {
    if (values.size() != D)
      fail(field, fmt::format("has {} entries: allowed exactly {} (one per dimension, run.dimension = {})", values.size(), D, D));
    Vec<D> v;
    for (int d = 0; d < D; ++d) v[d] = values[d];
    return v;
  }
  template <int D, class Repeated>
  Vec<D> vec_or(const Repeated& values, const std::string& field, const Vec<D>& fallback) const {
    return values.empty() ? fallback : vec<D>(values, field);
  }
  template <int D>
  Vec<D> direction(const Vec<D>& v, const std::string& field) const {
    double n = 0;
    for (double x : v) n += x * x;
    if (!(n > 0)) fail(field, "is the zero vector: a direction needs a non-zero length");
    Vec<D> u;
    for (int d = 0; d < D; ++d) u[d] = v[d] / std::sqrt(n);
    return u;
  }

  template <int D>
  std::shared_ptr<SolidShape<D>> shape(const cases::FluidWall& w, const std::string& field) const {
    switch (w.shape_case()) {
      case cases::FluidWall::kContainer:
        return container_box<D>(vec<D>(w.container().lower(), field + ".container.lower"),
                                vec<D>(w.container().upper(), field + ".container.upper"));
      case cases::FluidWall::kSolidBox:
        return solid_box<D>(vec<D>(w.solid_box().lower(), field + ".solid_box.lower"),
                            vec<D>(w.solid_box().upper(), field + ".solid_box.upper"));
      case cases::FluidWall::kHalfSpace:
        return half_space<D>(vec<D>(w.half_space().point(), field + ".half_space.point"),
                             direction<D>(vec<D>(w.half_space().normal(), field + ".half_space.normal"), field + ".half_space.normal"));
      case cases::FluidWall::kTube:
        return tube_wall<D>(vec<D>(w.tube().origin(), field + ".tube.origin"),
                            direction<D>(vec<D>(w.tube().axis(), field + ".tube.axis"), field + ".tube.axis"), w.tube().length(),
                            w.tube().radius());
      case cases::FluidWall::kAnnularDisk: {
        const auto& a = w.annular_disk();
        if (a.inner_radius() >= a.outer_radius())
          fail(field + ".annular_disk.inner_radius", fmt::format("= {}: allowed < outer_radius ({})", a.inner_radius(), a.outer_radius()));
        return annular_disk<D>(vec<D>(a.origin(), field + ".annular_disk.origin"),
                               direction<D>(vec<D>(a.axis(), field + ".annular_disk.axis"), field + ".annular_disk.axis"),
                               a.thickness(), a.inner_radius(), a.outer_radius());
      }
      case cases::FluidWall::SHAPE_NOT_SET:
        break;
    }
    fail(field, "has no shape: allowed container, solid_box, half_space, tube, annular_disk");
  }

 private:
  std::string file_;
};

}  // namespace

template <int D>
FluidSetup<D> fluid_setup_from_case(const cases::Case& c, const std::filesystem::path& case_file) {
  const Reader in(case_file.string());
  if (!c.has_fluid()) throw CaseError(fmt::format("{}: section 'fluid' is missing: fluid_sph needs it", case_file.string()));
  const auto& f = c.fluid();
  FluidSetup<D> setup;
  auto& s = setup.settings;
  s.particle_spacing = f.particle_spacing();
  s.smoothing_length_ratio = f.smoothing_length_ratio();
  s.kernel = f.kernel() == cases::FluidCase::WENDLAND_C2 ? KernelType::wendland_c2 : KernelType::cubic_spline;
  s.rest_density = f.density();
  s.dynamic_viscosity = f.dynamic_viscosity();
  s.sound_speed = f.sound_speed();
  s.density_diffusion = f.density_diffusion();
  s.artificial_viscosity = f.artificial_viscosity();
  s.background_pressure = f.background_pressure();
  s.shifting = f.shifting();
  switch (f.shifting_density_correction()) {
    case cases::FluidCase::FIELD_AT_NEW_POSITION: s.shifting_density = FluidSettings<D>::ShiftingDensity::field_gradient; break;
    case cases::FluidCase::SHIFT_CONTINUITY: s.shifting_density = FluidSettings<D>::ShiftingDensity::continuity; break;
    default: s.shifting_density = FluidSettings<D>::ShiftingDensity::keep; break;
  }
  switch (f.shifting_speed()) {
    case cases::FluidCase::SHIFT_BY_OWN_SPEED: s.shifting_speed = FluidSettings<D>::ShiftingSpeed::own_speed; break;
    case cases::FluidCase::SHIFT_BY_OWN_SPEED_AWAY_FROM_LEAFLETS:
      s.shifting_speed = FluidSettings<D>::ShiftingSpeed::own_speed_away_from_surfaces;
      break;
    default: s.shifting_speed = FluidSettings<D>::ShiftingSpeed::fastest_particle; break;
  }
  if (f.has_shifting_speed() && s.shifting == 0)
    in.fail("shifting_speed", fmt::format("= {}, but shifting is 0: set shifting > 0 or remove it (no shift to scale)",
                                          cases::FluidCase::ShiftingSpeed_Name(f.shifting_speed())));
  if (s.shifting_density != FluidSettings<D>::ShiftingDensity::keep && s.shifting == 0)
    in.fail("shifting_density_correction", fmt::format("= {}, but shifting is 0: set shifting > 0 or remove it (no shift, nothing to correct)",
                                                       cases::FluidCase::ShiftingDensityCorrection_Name(f.shifting_density_correction())));
  s.gravity = in.vec_or<D>(f.gravity(), "gravity", Vec<D>{});
  s.cfl = f.cfl();
  s.max_density_deviation = f.max_density_deviation();
  s.min_time_step_ratio = f.min_time_step_ratio();
  s.max_leak_fraction = f.max_leak_fraction();
  if (f.max_time_step() > 0) s.max_time_step = f.max_time_step();
  s.domain_lower = in.vec<D>(f.domain_lower(), "domain_lower");
  s.domain_upper = in.vec<D>(f.domain_upper(), "domain_upper");
  for (int d = 0; d < D; ++d)
    if (!(s.domain_upper[d] > s.domain_lower[d]))
      in.fail(fmt::format("domain_upper[{}]", d), fmt::format("= {}: allowed > domain_lower[{}] = {}", s.domain_upper[d], d, s.domain_lower[d]));
  if (!f.periodic().empty()) {
    if (f.periodic().size() != D) in.fail("periodic", fmt::format("has {} entries: allowed {} or none", f.periodic().size(), D));
    for (int d = 0; d < D; ++d) s.periodic[d] = f.periodic(d);
  }
  for (int k = 0; k < f.mirror_planes_size(); ++k) {
    const std::string field = fmt::format("mirror_planes[{}]", k);
    MirrorPlane<D> plane;
    plane.point = in.vec<D>(f.mirror_planes(k).point(), field + ".point");
    plane.normal = in.direction<D>(in.vec<D>(f.mirror_planes(k).normal(), field + ".normal"), field + ".normal");
    s.mirror_planes.push_back(plane);
  }
  if (s.mirror_planes.size() > 1) {
    try {
      (void)compound_mirror_maps<D>(s.mirror_planes);
    } catch (const std::invalid_argument& e) {
      in.fail("mirror_planes", fmt::format("({} planes): {}", s.mirror_planes.size(), e.what()));
    }
  }
  setup.scene.lattice_origin = in.vec_or<D>(f.lattice_origin(), "lattice_origin", Vec<D>{});
  if (f.fill_lattice() == cases::FluidCase::HEX_PRISM) {
    if (D != 3) in.fail("fill_lattice", fmt::format("= HEX_PRISM with run.dimension = {}: allowed only CUBIC in 2D", D));
    setup.scene.lattice = FillLattice::hex_prism;
    if (f.lattice_axis().empty()) in.fail("lattice_axis", "is missing: fill_lattice HEX_PRISM needs the axis its layers stack along");
    if (f.lattice_row_direction().empty())
      in.fail("lattice_row_direction", "is missing: fill_lattice HEX_PRISM needs the direction of one family of rows");
    setup.scene.lattice_axis = in.direction<D>(in.vec<D>(f.lattice_axis(), "lattice_axis"), "lattice_axis");
    setup.scene.lattice_row_direction =
        in.direction<D>(in.vec<D>(f.lattice_row_direction(), "lattice_row_direction"), "lattice_row_direction");
    if (const std::string why = fill_lattice_mismatch<D>(setup.scene, s); !why.empty())
      in.fail("fill_lattice", "= HEX_PRISM: " + why);
  } else if (!f.lattice_axis().empty() || !f.lattice_row_direction().empty()) {
    in.fail(f.lattice_axis().empty() ? "lattice_row_direction" : "lattice_axis",
            "is given, but fill_lattice is CUBIC: allowed only with fill_lattice HEX_PRISM");
  }
  setup.wall_layers = f.wall_layers();

  for (int k = 0; k < f.fluid_blocks_size(); ++k) {
    const std::string field = fmt::format("fluid_blocks[{}]", k);
    const auto& b = f.fluid_blocks(k);
    if (!b.has_box()) in.fail(field + ".box", "is missing: a fluid block needs its box");
    FluidBlock<D> block;
    block.lower = in.vec<D>(b.box().lower(), field + ".box.lower");
    block.upper = in.vec<D>(b.box().upper(), field + ".box.upper");
    if (!b.velocity().empty()) {
      const Vec<D> u = in.vec<D>(b.velocity(), field + ".velocity");
      block.velocity = [u](const Vec<D>&) { return u; };
    }
    setup.scene.fluid.push_back(block);
  }
  if (setup.scene.fluid.empty()) in.fail("fluid_blocks", "is empty: at least one block of fluid is needed");
  for (int k = 0; k < f.walls_size(); ++k) setup.scene.walls.push_back(in.shape<D>(f.walls(k), fmt::format("walls[{}]", k)));

  std::shared_ptr<const PressureWaveform> waveform;
  for (int k = 0; k < f.plates_size(); ++k) {
    const std::string field = fmt::format("plates[{}]", k);
    const auto& pc = f.plates(k);
    if (!pc.has_shape()) in.fail(field + ".shape", "is missing: allowed solid_box or annular_disk");
    setup.scene.plates.push_back(in.shape<D>(pc.shape(), field + ".shape"));
    PressurePlate<D> plate;
    plate.normal = in.direction<D>(in.vec<D>(pc.normal(), field + ".normal"), field + ".normal");
    plate.area = pc.area();
    plate.mass = pc.mass();
    const double offset = pc.pressure_mmhg() * kPascalPerMmHg;
    if (pc.pressure_source() != cases::FluidPressurePlate::CONSTANT && !waveform) {
      if (!c.has_waveform())
        in.fail(field + ".pressure_source", "uses the waveform, but the case has no 'waveform' section");
      waveform = std::make_shared<const PressureWaveform>(c.waveform(), case_file.string());
    }
    switch (pc.pressure_source()) {
      case cases::FluidPressurePlate::VENTRICULAR:
        plate.pressure = [waveform, offset](double t) { return waveform->ventricular_pressure(t) + offset; };
        break;
      case cases::FluidPressurePlate::AORTIC:
        plate.pressure = [waveform, offset](double t) { return waveform->aortic_pressure(t) + offset; };
        break;
      case cases::FluidPressurePlate::TRANSVALVULAR:
        plate.pressure = [waveform, offset](double t) { return waveform->transvalvular_pressure(t) + offset; };
        break;
      default:
        plate.pressure = [offset](double) { return offset; };
    }
    if (pc.travel_range_size() != 0) {
      if (pc.travel_range_size() != 2 || pc.travel_range(0) > 0 || pc.travel_range(1) < 0) {
        std::string values;
        for (double v : pc.travel_range()) values += (values.empty() ? "" : ", ") + fmt::format("{}", v);
        in.fail(field + ".travel_range", "= [" + values + "]: allowed two values, [least <= 0, most >= 0] (m), or none");
      }
      plate.min_displacement = pc.travel_range(0);
      plate.max_displacement = pc.travel_range(1);
    }
    setup.plates.push_back(plate);
  }
  s.plates_never_pull = f.plates_never_pull();
  s.plate_pressure_floor = f.plate_pressure_floor_mmhg() * kPascalPerMmHg;
  if (s.plates_never_pull && setup.plates.empty())
    in.fail("plates_never_pull", "= true, but the case has no plates: allowed only with at least one entry in fluid.plates");
  s.plate_floor_once_reached = f.plate_pressure_floor_once_reached();
  if (s.plate_floor_once_reached && !s.plates_never_pull)
    in.fail("plate_pressure_floor_once_reached", "= true, but plates_never_pull is false: set plates_never_pull: true or remove it");
  if (!s.plates_never_pull && f.plate_pressure_floor_mmhg() != 0)
    in.fail("plate_pressure_floor_mmHg", fmt::format("= {}, but plates_never_pull is false: set plates_never_pull: true or remove it",
                                                     f.plate_pressure_floor_mmhg()));

  const auto& pr = f.probes();
  for (int k = 0; k < pr.pressure_points_size(); ++k)
    setup.probes.pressure_points.push_back(
        {pr.pressure_points(k).name(), in.vec<D>(pr.pressure_points(k).position(), fmt::format("probes.pressure_points[{}].position", k))});
  auto planes = [&](const auto& list, const std::string& field, std::vector<NamedPlane<D>>& out) {
    for (int k = 0; k < list.size(); ++k) {
      const auto& p = list[k];
      const std::string name = fmt::format("probes.{}[{}]", field, k);
      ProbePlane<D> plane;
      plane.point = in.vec<D>(p.point(), name + ".point");
      plane.normal = in.direction<D>(in.vec<D>(p.normal(), name + ".normal"), name + ".normal");
      plane.radius = p.radius();
      out.push_back({p.name(), plane});
    }
  };
  planes(pr.flow_planes(), "flow_planes", setup.probes.flow_planes);
  planes(pr.velocity_planes(), "velocity_planes", setup.probes.velocity_planes);
  setup.probes.wall_forces = pr.wall_forces();
  return setup;
}

template <int D>
FluidSolver<D> make_solver(FluidSetup<D> setup) {
  Particles<D> particles = fill_particles(setup.scene, setup.settings, setup.wall_layers);
  for (std::size_t k = 0; k < setup.plates.size(); ++k) {
    auto& plate = setup.plates[k];
    if (plate.mass > 0) continue;
    std::size_t count = 0;
    for (std::size_t i = 0; i < particles.size(); ++i) count += particles.body[i] == k + 1;
    if (count == 0) throw CaseError(fmt::format("fluid.plates[{}]: its shape contains no lattice point: make it at least one particle spacing thick", k));
    plate.mass = static_cast<double>(count) * setup.settings.particle_mass();
  }
  return FluidSolver<D>(setup.settings, std::move(particles), std::move(setup.plates));
}

template FluidSetup<2> fluid_setup_from_case<2>(const cases::Case&, const std::filesystem::path&);
template FluidSetup<3> fluid_setup_from_case<3>(const cases::Case&, const std::filesystem::path&);
template FluidSolver<2> make_solver<2>(FluidSetup<2>);
template FluidSolver<3> make_solver<3>(FluidSetup<3>);

}  // namespace valvefsi::fluid
