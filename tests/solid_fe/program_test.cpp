// solid_fe as users run it: an FE-only run of a small plate ends with code 0 and writes its
// output; a case with a bad 2D strip, contact cylinder or missing mesh set ends with code 2 and
// a message naming the field.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <sys/wait.h>

#include "test_meshes.hpp"

namespace valvefsi::solid {
namespace {

std::filesystem::path prepare(const std::string& name, const std::string& run_extra, const std::string& solid_extra) {
  const auto dir = std::filesystem::temp_directory_path() / ("solid_program_test_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  Mesh mesh = testing::rectangular_plate(0.01, 0.005, 6, 3, 0.25e-3);
  mesh.node_sets["attachment"] = mesh.node_sets.at("left");
  write_mesh(dir / "plate.mesh.h5", mesh);
  std::ofstream(dir / "case.textproto")
      << "run { end_time: 0.002 snapshot_interval: 0.001 series_interval: 0.0005 " << run_extra << " }\n"
      << "waveform { period_s: 0.8 time_s: [0, 0.4] ventricular_pressure_mmHg: [10, 10] "
         "aortic_pressure_mmHg: [0, 0] }\n"
      << "solid { mesh_file: \"plate.mesh.h5\" " << solid_extra << " }\n";
  return dir;
}

int run(const std::filesystem::path& dir, const std::string& flags) {
  const std::string command = std::string(SOLID_FE_EXECUTABLE) + " --case " + (dir / "case.textproto").string() +
                              " --output " + (dir / "out").string() + " " + flags + " > " +
                              (dir / "log.txt").string() + " 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string log_of(const std::filesystem::path& dir) {
  std::ifstream in(dir / "log.txt");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(SolidProgram, FeOnlyRunWritesOutput) {
  const auto dir = prepare("ok", "", "material: OGDEN");
  EXPECT_EQ(run(dir, "--fe-only"), 0) << log_of(dir);
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "solid_fields.xdmf"));
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "solid_series.h5"));
  EXPECT_NE(log_of(dir).find("done: t = 0.002"), std::string::npos) << log_of(dir);
}

TEST(SolidProgram, TwoDimensionalRunWithoutAStripIsRefusedClearly) {
  const auto dir = prepare("nostrip", "dimension: 2", "");
  EXPECT_EQ(run(dir, "--fe-only"), 2);
  EXPECT_NE(log_of(dir).find("strip_front"), std::string::npos) << log_of(dir);
}

TEST(SolidProgram, BadContactCylinderIsReported) {
  const auto dir = prepare("badcylinder", "", "contact_cylinders { origin: [0, 0] axis: [0, 0, 1] radius: 0.01 }");
  EXPECT_EQ(run(dir, "--fe-only"), 2);
  EXPECT_NE(log_of(dir).find("solid.contact_cylinders[0]"), std::string::npos) << log_of(dir);
}

TEST(SolidProgram, MissingNodeSetIsReported) {
  const auto dir = prepare("badset", "fe_only: true", "fixed_node_sets: \"stent\"");
  EXPECT_EQ(run(dir, ""), 2);
  EXPECT_NE(log_of(dir).find("solid.fixed_node_sets"), std::string::npos) << log_of(dir);
}

TEST(SolidProgram, DiastolicDampingIsRefusedInACoupledRun) {
  // Without --fe-only (and run.fe_only) solid_fe is the coupler's participant: the FE-only
  // option is refused before it connects.
  const auto dir = prepare("diastolic_coupled", "", "diastolic_mass_damping_per_s: 200");
  EXPECT_EQ(run(dir, ""), 2);
  EXPECT_NE(log_of(dir).find("solid.diastolic_mass_damping_per_s"), std::string::npos) << log_of(dir);
  const auto fe_only = prepare("diastolic_fe_only", "", "diastolic_mass_damping_per_s: 200");
  EXPECT_EQ(run(fe_only, "--fe-only"), 0) << log_of(fe_only);
  EXPECT_NE(log_of(fe_only).find("diastolic mass-proportional damping ON"), std::string::npos) << log_of(fe_only);
}

}  // namespace
}  // namespace valvefsi::solid
