#pragma once
// The version of the wire protocol (proto/coupling.proto) this build speaks. Every Envelope
// carries it; a peer with another version is refused with a message naming both.

#include <cstdint>

#include "coupling.pb.h"

namespace valvefsi::coupling {

inline constexpr std::uint32_t kProtocolVersion = 1;
static_assert(kProtocolVersion == protocol::PROTOCOL_VERSION_CURRENT,
              "bump kProtocolVersion and PROTOCOL_VERSION_CURRENT in proto/coupling.proto together");

}  // namespace valvefsi::coupling
