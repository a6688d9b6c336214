#pragma once
// A coupled run of real processes for the tests: writes a case into a fresh folder, starts
// the coupler and two participants (stand-ins by default), and reads the results back.

#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "process_harness.hpp"

namespace valvefsi::testing {

// Paths of the built programs (compile definitions set by tests/coupler/CMakeLists.txt).
std::string coupler_exe();
std::string standin_exe(const std::string& name);  // "standin_solid_plate", ...

struct RunSpec {
  std::string name;                 // folder name
  double end_time = 0.05;
  std::string coupling;             // extra CouplingCase fields (text format)
  double heartbeat_interval_s = 0.1;
  double peer_timeout_s = 3.0;
  double startup_timeout_s = 30.0;
  std::string fluid = "standin_fluid_pressure";
  std::vector<std::string> fluid_args;
  std::string solid = "standin_solid_plate";
  std::vector<std::string> solid_args;
  bool start_fluid = true;
  std::string endpoint;             // empty: ipc://<folder>/c.ipc
  std::vector<std::string> coupler_args;  // e.g. {"--restart", folder}
};

class CoupledRun {
 public:
  explicit CoupledRun(const RunSpec& spec);
  std::filesystem::path dir;
  std::filesystem::path case_file;
  std::unique_ptr<ChildProcess> coupler;
  std::unique_ptr<ChildProcess> solid;
  std::unique_ptr<ChildProcess> fluid;
  // Waits for all started processes; exit codes by role ("coupler", "solid", "fluid"); a role
  // missing from the map did not end within `timeout`.
  std::map<std::string, int> wait_all(std::chrono::duration<double> timeout);
};

// A 1-D or 2-D dataset of the coupling series (row-major).
std::vector<double> read_series(const std::filesystem::path& file, const std::string& dataset);

// The value printed by the solid stand-in as "final z = <value> m".
double final_plate_z(const std::string& solid_log);

}  // namespace valvefsi::testing
