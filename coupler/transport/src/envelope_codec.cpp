#include "valvefsi/coupling/envelope_codec.hpp"

#include <fmt/format.h>

#include <limits>

#include "valvefsi/coupling/protocol_version.hpp"
#include "valvefsi/coupling/transport_errors.hpp"

namespace valvefsi::coupling {

std::size_t stamp_envelope(protocol::Envelope& envelope, std::uint64_t sequence) {
  envelope.set_protocol_version(kProtocolVersion);
  envelope.set_sequence(sequence);
  return envelope.ByteSizeLong();
}

void encode_envelope_into(const protocol::Envelope& envelope, void* buffer, std::size_t size) {
  if (size > static_cast<std::size_t>(std::numeric_limits<int>::max()) ||
      !envelope.SerializeToArray(buffer, static_cast<int>(size))) {
    throw ProtocolError(fmt::format("cannot encode a '{}' message of {} bytes (protobuf limit 2 GB)",
                                    body_name(envelope), size));
  }
}

protocol::Envelope decode_envelope(const void* data, std::size_t size, std::string_view sender,
                                   std::string_view receiver) {
  protocol::Envelope envelope;
  const bool parsed = size <= static_cast<std::size_t>(std::numeric_limits<int>::max()) &&
                      envelope.ParseFromArray(data, static_cast<int>(size));
  // A version of 0 with no body is what stray bytes that happen to parse look like.
  if (!parsed || (envelope.protocol_version() == 0 &&
                  envelope.body_case() == protocol::Envelope::BODY_NOT_SET)) {
    throw ProtocolError(fmt::format(
        "{} sent a malformed message ({} bytes that are not a valvefsi.protocol.Envelope)", sender,
        size));
  }
  if (envelope.protocol_version() != kProtocolVersion) {
    throw ProtocolError(fmt::format(
        "protocol version mismatch: {} speaks coupling protocol version {}, {} speaks version {} "
        "(rebuild both against the same proto/coupling.proto)",
        sender, envelope.protocol_version(), receiver, kProtocolVersion));
  }
  if (envelope.body_case() == protocol::Envelope::BODY_NOT_SET) {
    throw ProtocolError(fmt::format("{} sent a message with no body (sequence {})", sender,
                                    envelope.sequence()));
  }
  return envelope;
}

std::string body_name(const protocol::Envelope& envelope) {
  if (envelope.body_case() == protocol::Envelope::BODY_NOT_SET) return "empty";
  const auto* field = protocol::Envelope::descriptor()->FindFieldByNumber(envelope.body_case());
  return field != nullptr ? field->name() : fmt::format("body {}", static_cast<int>(envelope.body_case()));
}

}  // namespace valvefsi::coupling
