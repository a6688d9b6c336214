// The fluid section of a case file becomes settings, geometry, plates and probes; mistakes are
// reported with the file, the field, the value and what is allowed.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/fluid/case_setup.hpp"

namespace valvefsi::fluid {
namespace {

const std::string kChannel = R"(
run { end_time: 0.1 dimension: 2 }
fluid {
  particle_spacing: 0.01
  kernel: WENDLAND_C2
  sound_speed: 30
  gravity: [0, -9.81]
  domain_lower: [-0.1, -0.1]
  domain_upper: [1.1, 0.3]
  walls { half_space { point: [0, 0] normal: [0, 1] } }
  walls { half_space { point: [0, 0.2] normal: [0, -1] } }
  fluid_blocks { box { lower: [0, 0] upper: [1, 0.2] } }
  plates {
    shape { solid_box { lower: [-0.04, 0] upper: [0, 0.2] } }
    normal: [1, 0]  area: 0.2  pressure_mmHg: 10
  }
  probes {
    pressure_points { name: "mid" position: [0.5, 0.1] }
    flow_planes { name: "mid" point: [0.5, 0.1] normal: [1, 0] }
  }
}
)";

// The message of the CaseError that reading `text` as the fluid of `file` throws ("no error" if
// it throws none: the caller's EXPECT then fails with it).
template <int D>
std::string setup_error(const std::string& text, const std::string& file) {
  try {
    fluid_setup_from_case<D>(parse_case_text(text, file), file);
  } catch (const CaseError& e) {
    return e.what();
  }
  return "no error";
}
std::string case_error(const std::string& text) { return setup_error<2>(text, "channel.textproto"); }

TEST(CaseSetup, ReadsFluidSectionWithDefaults) {
  const cases::Case c = parse_case_text(kChannel, "channel.textproto");
  const FluidSetup<2> setup = fluid_setup_from_case<2>(c, "channel.textproto");
  EXPECT_DOUBLE_EQ(setup.settings.particle_spacing, 0.01);
  EXPECT_EQ(setup.settings.kernel, KernelType::wendland_c2);
  EXPECT_DOUBLE_EQ(setup.settings.rest_density, 1056.0);       // default: blood
  EXPECT_DOUBLE_EQ(setup.settings.dynamic_viscosity, 0.0035);  // default: blood
  EXPECT_DOUBLE_EQ(setup.settings.gravity[1], -9.81);
  ASSERT_EQ(setup.plates.size(), 1u);
  EXPECT_NEAR(setup.plates[0].pressure(0.3), 10 * 133.322387415, 1e-9);
  EXPECT_EQ(setup.probes.pressure_points.at(0).name, "mid");
  // The scene fills: 100 x 20 fluid particles, plate particles as body 1.
  FluidSolver<2> solver = make_solver<2>(setup);
  EXPECT_EQ(solver.particles().count(Kind::fluid), 2000u);
  EXPECT_GT(solver.plates()[0].mass, 0.0);
}

TEST(CaseSetup, WrongVectorLengthNamesFileFieldAndAllowed) {
  std::string text = kChannel;
  text.replace(text.find("gravity: [0, -9.81]"), 19, "gravity: [0, -9.81, 0]");
  const cases::Case c = parse_case_text(text, "channel.textproto");
  try {
    fluid_setup_from_case<2>(c, "channel.textproto");
    FAIL() << "expected a CaseError";
  } catch (const CaseError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("channel.textproto"), std::string::npos) << message;
    EXPECT_NE(message.find("fluid.gravity"), std::string::npos) << message;
    EXPECT_NE(message.find("has 3 entries"), std::string::npos) << message;
    EXPECT_NE(message.find("exactly 2"), std::string::npos) << message;
  }
}

TEST(CaseSetup, OutOfRangeValueIsRejectedByTheSchema) {
  std::string text = kChannel;
  text.replace(text.find("sound_speed: 30"), 15, "sound_speed: -3");
  EXPECT_THROW(parse_case_text(text, "channel.textproto"), CaseError);
}

TEST(CaseSetup, MirrorPlanesAreReadNormalisedAndChecked) {
  std::string text = kChannel;
  text.replace(text.find("  walls { half_space { point: [0, 0.2]"), 0,
               "  mirror_planes { point: [0, 0.1] normal: [0, -3] }\n");
  const cases::Case c = parse_case_text(text, "channel.textproto");
  const FluidSetup<2> setup = fluid_setup_from_case<2>(c, "channel.textproto");
  ASSERT_EQ(setup.settings.mirror_planes.size(), 1u);
  EXPECT_DOUBLE_EQ(setup.settings.mirror_planes[0].normal[1], -1.0);
  // The fill keeps only the half below the plane: 100 x 10 fluid particles.
  FluidSolver<2> solver = make_solver<2>(setup);
  EXPECT_EQ(solver.particles().count(Kind::fluid), 1000u);

  text.replace(text.find("normal: [0, -3]"), 15, "normal: [0, 0]");
  try {
    fluid_setup_from_case<2>(parse_case_text(text, "channel.textproto"), "channel.textproto");
    FAIL() << "expected a CaseError";
  } catch (const CaseError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("channel.textproto"), std::string::npos) << what;
    EXPECT_NE(what.find("mirror_planes[0].normal"), std::string::npos) << what;
    EXPECT_NE(what.find("zero vector"), std::string::npos) << what;
  }
}


// A small 3D sector wedge: fill_lattice HEX_PRISM with the sector's two planes sets up; a plane
// off the rows, the lattice in 2D and planes whose wedge is not 180/n degrees are refused by name.
const std::string kWedge = R"(
run { end_time: 0.1 dimension: 3 }
fluid {
  particle_spacing: 0.001
  domain_lower: [-0.004, -0.004, 0]
  domain_upper: [0.016, 0.016, 0.01]
  periodic: [false, false, true]
  mirror_planes { point: [0, 0, 0] normal: [0, 1, 0] }
  mirror_planes { point: [0, 0, 0] normal: [0.866025403784439, -0.5, 0] }
  fill_lattice: HEX_PRISM
  lattice_axis: [0, 0, 2]
  lattice_row_direction: [1, 0, 0]
  walls { tube { origin: [0, 0, -1] axis: [0, 0, 1] length: 2 radius: 0.01 } }
  fluid_blocks { box { lower: [-1, -1, -1] upper: [1, 1, 1] } }
}
)";

std::string setup_error_3d(const std::string& text) { return setup_error<3>(text, "wedge.textproto"); }

TEST(CaseSetup, HexPrismFillIsReadAndChecked) {
  const FluidSetup<3> setup = fluid_setup_from_case<3>(parse_case_text(kWedge, "wedge.textproto"), "wedge.textproto");
  EXPECT_EQ(setup.scene.lattice, FillLattice::hex_prism);
  EXPECT_DOUBLE_EQ(setup.scene.lattice_axis[2], 1.0);
  FluidSolver<3> solver = make_solver<3>(setup);
  // 10 layers of the 60-degree wedge of radius 10 dp: about pi 10^2 / 6 = 52 particles a layer.
  EXPECT_NEAR(static_cast<double>(solver.particles().count(Kind::fluid)) / 10.0, 52.4, 4.0);

  std::string off_rows = kWedge;
  off_rows.replace(off_rows.find("lattice_row_direction: [1, 0, 0]"), 32, "lattice_row_direction: [1, 1, 0]");
  std::string what = setup_error_3d(off_rows);
  EXPECT_NE(what.find("wedge.textproto: field 'fluid.fill_lattice' = HEX_PRISM: mirror_planes[0] does not run along a row"),
            std::string::npos) << what;

  std::string shifted = kWedge;
  shifted.replace(shifted.find("point: [0, 0, 0] normal: [0, 1, 0]"), 34, "point: [0, 0.0002, 0] normal: [0, 1, 0]");
  what = setup_error_3d(shifted);
  EXPECT_NE(what.find("mirror_planes[0] lies 0.2653 dp from the nearest row"), std::string::npos) << what;

  std::string wide = kWedge;
  wide.replace(wide.find("normal: [0.866025403784439, -0.5, 0]"), 36, "normal: [0.8, -0.6, 0]");
  what = setup_error_3d(wide);
  EXPECT_NE(what.find("field 'fluid.mirror_planes' (2 planes): mirror planes 0 and 1 bound a wedge of"), std::string::npos) << what;

  std::string flat = kChannel;
  flat.replace(flat.find("  walls {"), 0, "  fill_lattice: HEX_PRISM\n");
  try {
    fluid_setup_from_case<2>(parse_case_text(flat, "channel.textproto"), "channel.textproto");
    FAIL() << "expected a CaseError";
  } catch (const CaseError& e) {
    what = e.what();
    EXPECT_NE(what.find("channel.textproto: field 'fluid.fill_lattice' = HEX_PRISM with run.dimension = 2: allowed only CUBIC"),
              std::string::npos) << what;
  }
}

TEST(CaseSetup, PlatesNeverPullIsReadAndChecked) {
  std::string text = kChannel;
  text.replace(text.find("  probes {"), 0, "  plates_never_pull: true\n  plate_pressure_floor_mmHg: 2\n");
  const FluidSetup<2> setup = fluid_setup_from_case<2>(parse_case_text(text, "channel.textproto"), "channel.textproto");
  EXPECT_TRUE(setup.settings.plates_never_pull);
  EXPECT_NEAR(setup.settings.plate_pressure_floor, 2 * 133.322387415, 1e-9);
  EXPECT_FALSE(setup.settings.plate_floor_once_reached);
  std::string once = text;
  once.replace(once.find("  probes {"), 0, "  plate_pressure_floor_once_reached: true\n");
  EXPECT_TRUE(fluid_setup_from_case<2>(parse_case_text(once, "channel.textproto"), "channel.textproto").settings.plate_floor_once_reached);
  std::string once_alone = kChannel;
  once_alone.replace(once_alone.find("  probes {"), 0, "  plate_pressure_floor_once_reached: true\n");
  std::string what = case_error(once_alone);
  EXPECT_NE(what.find("channel.textproto: field 'fluid.plate_pressure_floor_once_reached' = true, but plates_never_pull is false"),
            std::string::npos) << what;

  std::string floor_only = kChannel;
  floor_only.replace(floor_only.find("  probes {"), 0, "  plate_pressure_floor_mmHg: 2\n");
  what = case_error(floor_only);
  EXPECT_NE(what.find("channel.textproto: field 'fluid.plate_pressure_floor_mmHg' = 2, but plates_never_pull is false"),
            std::string::npos) << what;
}

TEST(CaseSetup, PlateTravelRangeIsReadAndChecked) {
  std::string text = kChannel;
  const auto with_range = [&](const std::string& range) {
    std::string t = text;
    t.replace(t.find("pressure_mmHg: 10"), 17, "pressure_mmHg: 10 travel_range: " + range);
    return t;
  };
  const FluidSetup<2> bounded = fluid_setup_from_case<2>(parse_case_text(with_range("[-0.02, 0.1]"), "channel.textproto"), "channel.textproto");
  EXPECT_DOUBLE_EQ(bounded.plates.at(0).min_displacement, -0.02);
  EXPECT_DOUBLE_EQ(bounded.plates.at(0).max_displacement, 0.1);
  const FluidSetup<2> open = fluid_setup_from_case<2>(parse_case_text(text, "channel.textproto"), "channel.textproto");
  EXPECT_TRUE(std::isinf(open.plates.at(0).min_displacement) && open.plates.at(0).min_displacement < 0);
  EXPECT_TRUE(std::isinf(open.plates.at(0).max_displacement) && open.plates.at(0).max_displacement > 0);
  for (const std::string range : {"[0.01, 0.1]", "[-0.02]", "[-0.02, -0.01]"}) {
    const std::string what = case_error(with_range(range));
    EXPECT_NE(what.find("channel.textproto: field 'fluid.plates[0].travel_range' = ["), std::string::npos) << what;
    EXPECT_NE(what.find("allowed two values, [least <= 0, most >= 0]"), std::string::npos) << what;
  }
}

TEST(CaseSetup, ShiftingDensityCorrectionIsReadAndChecked) {
  using Mode = FluidSettings<2>::ShiftingDensity;
  EXPECT_EQ(fluid_setup_from_case<2>(parse_case_text(kChannel, "channel.textproto"), "channel.textproto").settings.shifting_density,
            Mode::keep);  // the default
  for (const auto& [name, mode] : {std::pair{"FIELD_AT_NEW_POSITION", Mode::field_gradient}, std::pair{"SHIFT_CONTINUITY", Mode::continuity}}) {
    std::string text = kChannel;
    text.replace(text.find("  probes {"), 0, std::string("  shifting: 1\n  shifting_density_correction: ") + name + "\n");
    EXPECT_EQ(fluid_setup_from_case<2>(parse_case_text(text, "channel.textproto"), "channel.textproto").settings.shifting_density, mode);
  }
  std::string without_shifting = kChannel;
  without_shifting.replace(without_shifting.find("  probes {"), 0, "  shifting_density_correction: SHIFT_CONTINUITY\n");
  const std::string what = case_error(without_shifting);
  EXPECT_NE(what.find("channel.textproto: field 'fluid.shifting_density_correction' = SHIFT_CONTINUITY, but shifting is 0"),
            std::string::npos) << what;
}

TEST(CaseSetup, ShiftingSpeedIsReadAndChecked) {
  using Speed = FluidSettings<2>::ShiftingSpeed;
  EXPECT_EQ(fluid_setup_from_case<2>(parse_case_text(kChannel, "channel.textproto"), "channel.textproto").settings.shifting_speed,
            Speed::fastest_particle);  // the default
  for (const auto& [name, speed] : {std::pair{"SHIFT_BY_OWN_SPEED", Speed::own_speed},
                                    std::pair{"SHIFT_BY_OWN_SPEED_AWAY_FROM_LEAFLETS", Speed::own_speed_away_from_surfaces}}) {
    std::string text = kChannel;
    text.replace(text.find("  probes {"), 0, std::string("  shifting: 1\n  shifting_speed: ") + name + "\n");
    EXPECT_EQ(fluid_setup_from_case<2>(parse_case_text(text, "channel.textproto"), "channel.textproto").settings.shifting_speed, speed);
  }
  std::string without_shifting = kChannel;
  without_shifting.replace(without_shifting.find("  probes {"), 0, "  shifting_speed: SHIFT_BY_OWN_SPEED\n");
  const std::string what = case_error(without_shifting);
  EXPECT_NE(what.find("channel.textproto: field 'fluid.shifting_speed' = SHIFT_BY_OWN_SPEED, but shifting is 0"), std::string::npos)
      << what;
}

}  // namespace
}  // namespace valvefsi::fluid
