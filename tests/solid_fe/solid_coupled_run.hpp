#pragma once
// A coupled run of the real solid_fe with the real coupler and a fluid participant (a stand-in
// or the tests' own strip fluid), as processes, in a fresh folder; and the FE-only twin.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "process_harness.hpp"
#include "valvefsi/solid/mesh.hpp"

namespace valvefsi::solid::testing {

struct SolidRunSpec {
  std::string name;
  Mesh mesh;
  std::string run_extra;       // extra RunCase fields
  std::string solid_extra;     // extra SolidCase fields
  std::string coupling_extra;  // extra CouplingCase fields
  std::string waveform = "waveform { period_s: 0.8 time_s: [0, 0.4] ventricular_pressure_mmHg: [0, 0] "
                         "aortic_pressure_mmHg: [0, 0] }";
  double end_time = 0.01;
  std::string fluid_exe;       // absolute path
  std::vector<std::string> fluid_args;
  std::vector<std::string> coupler_args;  // e.g. {"--restart", folder}
  std::vector<std::string> solid_args;    // e.g. FE-only {"--restart", folder}
  std::string output_dir;                 // default: the run's fresh folder
};

class SolidCoupledRun {
 public:
  // Writes mesh and case; starts coupler, solid_fe (participant) and the fluid.
  explicit SolidCoupledRun(const SolidRunSpec& spec, bool fe_only = false);
  std::filesystem::path dir;     // the case and logs
  std::filesystem::path output;  // the programs' output folder (dir unless the spec names one)
  std::unique_ptr<valvefsi::testing::ChildProcess> coupler, solid, fluid;
  // Exit code of the solid (-1 if it did not end within the timeout); waits for all.
  int wait(double timeout_s);
  // Last sample of /monitor/<set>/position in the solid's series file (3 x nodes).
  Eigen::Matrix3Xd final_monitor(const std::string& set, const std::string& series = "solid_series.h5") const;
  std::string logs() const;
};

}  // namespace valvefsi::solid::testing
