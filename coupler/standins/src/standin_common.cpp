#include "standin_common.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <thread>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/coupling/endpoint.hpp"

namespace valvefsi::standins {

void add_common_options(CLI::App& app, StandinSettings& settings) {
  app.add_option("--case", settings.case_file, "case file (its coupling part gives endpoint and timeouts)")->required();
  app.add_option("--output", settings.output_dir, "run output folder (default: the case's run.output_dir)");
  app.add_option("--endpoint", settings.endpoint, "coupler endpoint (overrides the case and the environment)");
  app.add_option("--step-seconds", settings.step_seconds, "wall-clock seconds of pretend work per window")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--nan-at-window", settings.nan_at_window, "test: put a NaN into this window's output");
  app.add_option("--exit-at-window", settings.exit_at_window, "test: exit(7) silently at this window");
  app.add_option("--fail-at-window", settings.fail_at_window,
                 "test: fail with an error at this window (the others hear an abort; exit code 2)");
}

coupling::ParticipantOptions participant_options(const StandinSettings& settings, coupling::ParticipantRole role,
                                                 const std::string& solver_name) {
  const auto run_case = load_case(settings.case_file);
  const std::string output = settings.output_dir.empty() ? run_case.run().output_dir() : settings.output_dir;
  coupling::ParticipantOptions options;
  options.role = role;
  options.solver_name = solver_name;
  options.solver_version = "1.0";
  options.endpoint = settings.endpoint.empty() ? coupling::resolve_endpoint(run_case.coupling().endpoint(), output)
                                               : settings.endpoint;
  options.spatial_dimension = 3;
  options.can_checkpoint = true;
  options.liveness.heartbeat_interval = std::chrono::duration<double>(run_case.coupling().heartbeat_interval_s());
  options.liveness.peer_timeout = std::chrono::duration<double>(run_case.coupling().peer_timeout_s());
  options.liveness.startup_timeout = std::chrono::duration<double>(run_case.coupling().startup_timeout_s());
  return options;
}

int run_guarded(const std::string& name, std::unique_ptr<coupling::Participant>& participant,
                const std::function<void()>& body) {
  spdlog::set_pattern("%H:%M:%S.%e %^%l%$ %v");
  try {
    body();
    return coupling::kExitOk;
  } catch (const coupling::TransportError& error) {
    spdlog::error("{}: {}", name, error.what());
    if (participant) participant->abort(error.what());
    return error.exit_code();
  } catch (const std::exception& error) {
    spdlog::error("{}: {}", name, error.what());
    if (participant) participant->abort(error.what());
    return coupling::kExitBadInput;
  }
}

void simulate_step(const StandinSettings& settings, std::uint64_t window_index) {
  if (settings.step_seconds > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(settings.step_seconds));
  if (settings.exit_at_window >= 0 && window_index == static_cast<std::uint64_t>(settings.exit_at_window)) {
    std::_Exit(7);
  }
  if (settings.fail_at_window >= 0 && window_index == static_cast<std::uint64_t>(settings.fail_at_window)) {
    throw std::runtime_error("test: a deliberate failure at window " + std::to_string(window_index));
  }
}

}  // namespace valvefsi::standins
