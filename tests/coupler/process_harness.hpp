#pragma once
// Real processes for the multi-process coupler tests: spawn with output to a log file, wait
// with a deadline, signal, and always reap (a test never leaves a process behind).

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace valvefsi::testing {

class ChildProcess {
 public:
  // Starts `argv` (argv[0] an absolute path) with stdout and stderr to `log`, in its own
  // process group. Extra `environment` entries ("NAME=value") are added to ours.
  ChildProcess(std::vector<std::string> argv, std::filesystem::path log, std::vector<std::string> environment = {});
  ~ChildProcess();  // SIGKILLs and reaps the group if still running
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  // Exit code (128 + signal when killed by one) once the process ended within `timeout`.
  std::optional<int> wait_for_exit(std::chrono::duration<double> timeout);
  [[nodiscard]] bool running();
  void send_signal(int signal_number);  // to the process group
  [[nodiscard]] std::string log_text() const;
  [[nodiscard]] pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
  std::optional<int> exit_code_;
  std::filesystem::path log_;
};

// A fresh, empty folder under the system's temporary folder, short enough for ipc sockets.
std::filesystem::path fresh_directory(const std::string& name);

// Writes `text` to `path`.
void write_file(const std::filesystem::path& path, const std::string& text);

}  // namespace valvefsi::testing
