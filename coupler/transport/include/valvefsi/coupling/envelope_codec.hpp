#pragma once
// Envelope <-> bytes. Decoding is where a malformed message or a protocol version mismatch is
// caught: both throw ProtocolError naming the sender and, for a mismatch, both versions.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "coupling.pb.h"

namespace valvefsi::coupling {

// Stamps `envelope` with kProtocolVersion and `sequence`; returns its encoded size in bytes.
std::size_t stamp_envelope(protocol::Envelope& envelope, std::uint64_t sequence);

// Writes a stamped envelope into `buffer` of exactly stamp_envelope()'s size.
void encode_envelope_into(const protocol::Envelope& envelope, void* buffer, std::size_t size);

// Parses bytes received from `sender` (e.g. "participant 'fluid'"). Throws ProtocolError when
// the bytes are not an Envelope, carry no body, or carry another protocol version; `receiver`
// names this side in the mismatch message ("the coupler", "participant 'fluid'").
protocol::Envelope decode_envelope(const void* data, std::size_t size, std::string_view sender,
                                   std::string_view receiver);

// "handshake", "window_done", ... for logs and out-of-order messages.
std::string body_name(const protocol::Envelope& envelope);

}  // namespace valvefsi::coupling
