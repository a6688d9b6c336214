// coupler --case FILE [--output DIR] [--endpoint E] [--heartbeat-interval S] [--peer-timeout S]
//         [--startup-timeout S]
//         [--restart FOLDER] [--describe-launch]
// Couples the fluid and the solid of a case (its `coupling` part), see docs/coupling.md.

#include <CLI/CLI.hpp>
#include <spdlog/cfg/env.h>
#include <spdlog/spdlog.h>

#include <iostream>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/coupler/coupler_run.hpp"
#include "valvefsi/coupler/launch_plan.hpp"
#include "valvefsi/coupler/restart_points.hpp"
#include "valvefsi/coupling/restart_points.hpp"
#include "valvefsi/coupling/transport_errors.hpp"

int main(int argc, char** argv) {
  // SPDLOG_LEVEL=debug shows every implicit iteration's residual (docs/coupling.md).
  spdlog::cfg::load_env_levels();
  CLI::App app{"valvefsi coupler: couples fluid_sph and solid_fe (or any participants) through ZeroMQ"};
  std::string case_file;
  std::string output_dir;
  std::string endpoint;
  double heartbeat_interval = 0.0;
  double peer_timeout = 0.0;
  double startup_timeout = 0.0;
  app.add_option("--case", case_file, "case file (protobuf text format, message valvefsi.cases.Case)")->required();
  app.add_option("--output", output_dir, "run output folder (default: the case's run.output_dir)");
  app.add_option("--endpoint", endpoint, "ZeroMQ endpoint to bind, e.g. tcp://127.0.0.1:5570 (overrides the case)");
  app.add_option("--heartbeat-interval", heartbeat_interval, "seconds between heartbeats (overrides the case)")
      ->check(CLI::PositiveNumber);
  app.add_option("--peer-timeout", peer_timeout, "seconds of silence after which a participant is lost (overrides the case)")
      ->check(CLI::PositiveNumber);
  app.add_option("--startup-timeout", startup_timeout, "seconds the participants get to connect (overrides the case)")
      ->check(CLI::PositiveNumber);
  std::string restart;
  app.add_option("--restart", restart,
                 "continue a run from restart data: a run's restart/ folder (its newest complete point) or one "
                 "restart/t_<time>/ folder");
  bool describe_launch = false;
  app.add_flag("--describe-launch", describe_launch,
               "print the programs, arguments, output folder and endpoint of the case as JSON and exit "
               "(used by scripts/run_case.py)");
  CLI11_PARSE(app, argc, argv);
  spdlog::set_pattern("%H:%M:%S.%e %^%l%$ %v");

  try {
    const auto run_case = valvefsi::load_case(case_file);
    const std::filesystem::path output = output_dir.empty() ? std::filesystem::path(run_case.run().output_dir())
                                                            : std::filesystem::path(output_dir);
    if (describe_launch) {
      std::cout << valvefsi::coupler::launch_plan_json(case_file, run_case, output) << '\n';
      return 0;
    }
    std::filesystem::create_directories(output);
    auto settings = valvefsi::coupler::settings_from_case(run_case, output);
    if (!endpoint.empty()) settings.endpoint = endpoint;
    if (heartbeat_interval > 0.0) settings.liveness.heartbeat_interval = std::chrono::duration<double>(heartbeat_interval);
    if (peer_timeout > 0.0) settings.liveness.peer_timeout = std::chrono::duration<double>(peer_timeout);
    if (startup_timeout > 0.0) settings.liveness.startup_timeout = std::chrono::duration<double>(startup_timeout);
    valvefsi::coupling::check_liveness_settings(settings.liveness);
    if (!restart.empty()) {
      settings.restart_from = std::filesystem::absolute(valvefsi::coupling::resolve_restart_folder(restart, {"coupler", "fluid", "solid"}));
      settings.restart_time = valvefsi::coupler::restart_folder_time(settings.restart_from);
      if (settings.restart_time >= settings.end_time) {
        spdlog::error("coupler: --restart {}: the restart point t = {} s is not before run.end_time = {} s", restart,
                      settings.restart_time, settings.end_time);
        return valvefsi::coupling::kExitBadInput;
      }
    }
    return valvefsi::coupler::run_coupler(settings);
  } catch (const valvefsi::CaseError& error) {
    spdlog::error("coupler: {}", error.what());
    return valvefsi::coupling::kExitBadInput;
  } catch (const std::exception& error) {
    spdlog::error("coupler: {}", error.what());
    return valvefsi::coupling::kExitBadInput;
  }
}
