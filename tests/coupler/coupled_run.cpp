#include "coupled_run.hpp"

#include <fmt/format.h>
#include <hdf5.h>

#include <regex>
#include <stdexcept>
#include <thread>

namespace valvefsi::testing {

std::string coupler_exe() { return VALVEFSI_TEST_COUPLER_EXE; }
std::string standin_exe(const std::string& name) { return std::string(VALVEFSI_TEST_STANDIN_DIR) + "/" + name; }

CoupledRun::CoupledRun(const RunSpec& spec) : dir(fresh_directory(spec.name)), case_file(dir / "case.textproto") {
  write_file(case_file, fmt::format(R"(run {{ end_time: {} output_dir: "{}" }}
coupling {{
  endpoint: "{}"
  heartbeat_interval_s: {}
  peer_timeout_s: {}
  startup_timeout_s: {}
  {}
}}
)",
                                    spec.end_time, dir.string(),
                                    spec.endpoint.empty() ? "ipc://" + dir.string() + "/c.ipc" : spec.endpoint,
                                    spec.heartbeat_interval_s,
                                    spec.peer_timeout_s, spec.startup_timeout_s, spec.coupling));
  const std::vector<std::string> common = {"--case", case_file.string(), "--output", dir.string()};
  auto with = [&](std::vector<std::string> argv, const std::vector<std::string>& extra) {
    argv.insert(argv.end(), extra.begin(), extra.end());
    argv.insert(argv.end(), common.begin(), common.end());
    return argv;
  };
  coupler = std::make_unique<ChildProcess>(with({coupler_exe()}, spec.coupler_args), dir / "coupler.log");
  solid = std::make_unique<ChildProcess>(with({standin_exe(spec.solid)}, spec.solid_args), dir / "solid.log");
  if (spec.start_fluid) {
    fluid = std::make_unique<ChildProcess>(with({standin_exe(spec.fluid)}, spec.fluid_args), dir / "fluid.log");
  }
}

std::map<std::string, int> CoupledRun::wait_all(std::chrono::duration<double> timeout) {
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(timeout);
  std::map<std::string, int> codes;
  for (auto& [role, process] : {std::pair{"coupler", coupler.get()}, std::pair{"solid", solid.get()},
                                std::pair{"fluid", fluid.get()}}) {
    if (process == nullptr) continue;
    const auto left = std::max(std::chrono::steady_clock::duration::zero(), deadline - std::chrono::steady_clock::now());
    if (auto code = process->wait_for_exit(left)) codes[role] = *code;
  }
  return codes;
}

std::vector<double> read_series(const std::filesystem::path& file, const std::string& dataset) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) throw std::runtime_error("cannot open " + file.string());
  const hid_t d = H5Dopen2(f, dataset.c_str(), H5P_DEFAULT);
  const hid_t space = H5Dget_space(d);
  const auto count = static_cast<std::size_t>(H5Sget_simple_extent_npoints(space));
  std::vector<double> values(count);
  if (count > 0) H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
  H5Sclose(space);
  H5Dclose(d);
  H5Fclose(f);
  return values;
}

double final_plate_z(const std::string& solid_log) {
  static const std::regex pattern(R"(final z = ([-+0-9.eE]+) m)");
  std::smatch match;
  if (!std::regex_search(solid_log, match, pattern)) throw std::runtime_error("no final z in the solid's log:\n" + solid_log);
  return std::stod(match[1].str());
}

}  // namespace valvefsi::testing
