#pragma once
// What every stand-in participant shares: the command line the launcher gives every program
// (--case CASE --output DIR), the participant options derived from the case, fault injection
// for the tests, and a guard that turns any failure into an Abort and an exit code.

#include <CLI/CLI.hpp>

#include <functional>
#include <memory>
#include <string>

#include "valvefsi/coupling/participant.hpp"

namespace valvefsi::standins {

struct StandinSettings {
  std::string case_file;
  std::string output_dir;
  std::string endpoint;          // overrides the case
  double step_seconds = 0.0;     // wall-clock work per window, to stand in for a real step
  long nan_at_window = -1;       // put a NaN into the output of this window (tests)
  long exit_at_window = -1;      // exit(7) without a word at this window (tests)
  long fail_at_window = -1;      // fail with an error at this window: abort sent, exit 2 (tests)
};

// Adds the shared options to `app`.
void add_common_options(CLI::App& app, StandinSettings& settings);

// Participant options from the case's coupling part and the command line.
coupling::ParticipantOptions participant_options(const StandinSettings& settings, coupling::ParticipantRole role,
                                                 const std::string& solver_name);

// Runs `body` (which constructs the participant into `participant`); on any error logs it,
// sends Abort when a participant exists, and returns the error's exit code.
int run_guarded(const std::string& name, std::unique_ptr<coupling::Participant>& participant,
                const std::function<void()>& body);

// The work a real solver would do in a window: sleeps step_seconds, then applies the test faults.
void simulate_step(const StandinSettings& settings, std::uint64_t window_index);

}  // namespace valvefsi::standins
