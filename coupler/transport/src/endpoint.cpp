#include "valvefsi/coupling/endpoint.hpp"

#include <fmt/format.h>

#include <cstdlib>
#include <functional>

namespace valvefsi::coupling {

namespace {
// sun_path holds 108 bytes including the terminating zero.
constexpr std::size_t kMaxUnixSocketPath = 107;
}  // namespace

std::string default_endpoint(const std::filesystem::path& output_dir) {
  const std::filesystem::path folder = std::filesystem::weakly_canonical(std::filesystem::absolute(output_dir));
  const std::string in_folder = (folder / "coupler.ipc").string();
  if (in_folder.size() <= kMaxUnixSocketPath) return "ipc://" + in_folder;
  const std::size_t hash = std::hash<std::string>{}(folder.string());
  return fmt::format("ipc:///tmp/valvefsi-{:016x}.ipc", hash);
}

std::string resolve_endpoint(const std::string& configured, const std::filesystem::path& output_dir) {
  if (const char* from_environment = std::getenv(kEndpointEnvironmentVariable);
      from_environment != nullptr && *from_environment != '\0') {
    return from_environment;
  }
  if (!configured.empty()) return configured;
  return default_endpoint(output_dir);
}

std::filesystem::path ipc_socket_file(const std::string& endpoint) {
  constexpr std::string_view kScheme = "ipc://";
  if (endpoint.rfind(kScheme, 0) != 0) return {};
  return endpoint.substr(kScheme.size());
}

}  // namespace valvefsi::coupling
