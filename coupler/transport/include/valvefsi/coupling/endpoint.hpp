#pragma once
// Where the coupler and its participants meet. The default is a Unix-domain socket in the
// run's output folder, so concurrent runs never collide; both sides derive it the same way.

#include <filesystem>
#include <string>

namespace valvefsi::coupling {

// Environment variable through which the launcher hands every program the same endpoint.
inline constexpr const char* kEndpointEnvironmentVariable = "VALVEFSI_COUPLER_ENDPOINT";

// "ipc://<abs output_dir>/coupler.ipc", or, when that path is too long for a Unix socket
// (~107 bytes), "ipc:///tmp/valvefsi-<hash of the folder>.ipc".
std::string default_endpoint(const std::filesystem::path& output_dir);

// The endpoint to use: the environment variable if set, else `configured` if non-empty,
// else default_endpoint(output_dir).
std::string resolve_endpoint(const std::string& configured, const std::filesystem::path& output_dir);

// For "ipc://PATH" the socket file PATH, else empty (tcp:// needs no clean-up).
std::filesystem::path ipc_socket_file(const std::string& endpoint);

}  // namespace valvefsi::coupling
