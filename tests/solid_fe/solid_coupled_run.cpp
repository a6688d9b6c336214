#include "solid_coupled_run.hpp"

#include <chrono>
#include <stdexcept>

#include <fmt/format.h>
#include <hdf5.h>

#include "coupled_run.hpp"

namespace valvefsi::solid::testing {

SolidCoupledRun::SolidCoupledRun(const SolidRunSpec& spec, bool fe_only)
    : dir(valvefsi::testing::fresh_directory(spec.name)),
      output(spec.output_dir.empty() ? dir : std::filesystem::path(spec.output_dir)) {
  write_mesh(dir / "strip.mesh.h5", spec.mesh);
  const auto case_file = dir / "case.textproto";
  valvefsi::testing::write_file(
      case_file,
      fmt::format("run {{ end_time: {} output_dir: \"{}\" series_interval: 0.001 {} {} }}\n"
                  "{}\nsolid {{ mesh_file: \"strip.mesh.h5\" {} }}\n"
                  "coupling {{ endpoint: \"ipc://{}/c.ipc\" heartbeat_interval_s: 0.1 peer_timeout_s: 2 "
                  "startup_timeout_s: 30 {} }}\n",
                  spec.end_time, dir.string(),
                  // run_extra may set its own snapshot interval (a field given twice is an error)
                  spec.run_extra.find("snapshot_interval") == std::string::npos ? "snapshot_interval: 0.005" : "",
                  spec.run_extra, spec.waveform, spec.solid_extra, dir.string(),
                  spec.coupling_extra));
  const std::vector<std::string> common = {"--case", case_file.string(), "--output", output.string()};
  auto with = [&](std::vector<std::string> argv, const std::vector<std::string>& extra) {
    argv.insert(argv.end(), extra.begin(), extra.end());
    argv.insert(argv.end(), common.begin(), common.end());
    return argv;
  };
  const std::vector<std::string> env = {"OMP_NUM_THREADS=1", "OMP_WAIT_POLICY=passive"};
  if (fe_only) {
    std::vector<std::string> args = {"--fe-only"};
    args.insert(args.end(), spec.solid_args.begin(), spec.solid_args.end());
    solid = std::make_unique<valvefsi::testing::ChildProcess>(with({SOLID_FE_EXECUTABLE}, args), dir / "solid.log", env);
    return;
  }
  coupler = std::make_unique<valvefsi::testing::ChildProcess>(with({valvefsi::testing::coupler_exe()}, spec.coupler_args),
                                                              dir / "coupler.log");
  solid = std::make_unique<valvefsi::testing::ChildProcess>(with({SOLID_FE_EXECUTABLE}, {}), dir / "solid.log", env);
  fluid = std::make_unique<valvefsi::testing::ChildProcess>(with({spec.fluid_exe}, spec.fluid_args),
                                                            dir / "fluid.log");
}

int SolidCoupledRun::wait(double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  int code = -1;
  for (auto* p : {solid.get(), coupler.get(), fluid.get()}) {
    if (p == nullptr) continue;
    const auto left = std::max(std::chrono::steady_clock::duration::zero(),
                               std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                   deadline - std::chrono::steady_clock::now()));
    const auto c = p->wait_for_exit(left);
    if (p == solid.get()) code = c ? *c : -1;
  }
  return code;
}

Eigen::Matrix3Xd SolidCoupledRun::final_monitor(const std::string& set, const std::string& series) const {
  const auto file = output / series;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) throw std::runtime_error("cannot open " + file.string());
  const std::string name = "/monitor/" + set + "/position";
  const hid_t d = H5Dopen2(f, name.c_str(), H5P_DEFAULT);
  const hid_t space = H5Dget_space(d);
  hsize_t dims[3] = {0, 0, 0};
  H5Sget_simple_extent_dims(space, dims, nullptr);
  std::vector<double> values(dims[0] * dims[1] * dims[2]);
  if (!values.empty()) H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
  H5Sclose(space);
  H5Dclose(d);
  H5Fclose(f);
  if (dims[0] == 0) throw std::runtime_error("no samples in " + file.string());
  Eigen::Matrix3Xd last(3, static_cast<Eigen::Index>(dims[1]));
  for (hsize_t k = 0; k < dims[1]; ++k) {
    for (int c = 0; c < 3; ++c) last(c, static_cast<Eigen::Index>(k)) = values[((dims[0] - 1) * dims[1] + k) * 3 + c];
  }
  return last;
}

std::string SolidCoupledRun::logs() const {
  std::string text;
  for (const auto& [name, p] : {std::pair{"solid", solid.get()}, std::pair{"coupler", coupler.get()},
                                std::pair{"fluid", fluid.get()}}) {
    if (p != nullptr) text += fmt::format("--- {} ---\n{}\n", name, p->log_text());
  }
  return text;
}

}  // namespace valvefsi::solid::testing
