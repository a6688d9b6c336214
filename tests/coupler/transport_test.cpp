// The transport on its own, in one process: envelope encoding and its refusals (malformed
// bytes, a foreign version), the NaN check's message, packed arrays, endpoints, and the
// channel's liveness rules (a quiet live peer is kept, a closed or absent one is lost, an
// Abort ends the wait).

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <thread>

#include "process_harness.hpp"
#include "valvefsi/coupling/endpoint.hpp"
#include "valvefsi/coupling/envelope_codec.hpp"
#include "valvefsi/coupling/finite_check.hpp"
#include "valvefsi/coupling/message_channel.hpp"
#include "valvefsi/coupling/protocol_version.hpp"
#include "valvefsi/coupling/wire_arrays.hpp"

namespace valvefsi::coupling {
namespace {

using namespace std::chrono_literals;

template <class Error>
std::string message_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const Error& error) {
    return error.what();
  }
  return "(nothing thrown)";
}

TEST(EnvelopeCodec, RoundTripKeepsBodyVersionAndSequence) {
  protocol::Envelope out;
  out.mutable_window_command()->mutable_window()->set_time(0.25);
  out.mutable_window_command()->mutable_loads()->add_forces(1.5);
  const std::size_t size = stamp_envelope(out, 42);
  std::string bytes(size, '\0');
  encode_envelope_into(out, bytes.data(), size);
  const auto in = decode_envelope(bytes.data(), bytes.size(), "participant 'fluid'", "the coupler");
  EXPECT_EQ(in.protocol_version(), kProtocolVersion);
  EXPECT_EQ(in.sequence(), 42u);
  EXPECT_EQ(in.window_command().window().time(), 0.25);
  EXPECT_EQ(in.window_command().loads().forces(0), 1.5);
  EXPECT_EQ(body_name(in), "window_command");
}

TEST(EnvelopeCodec, MalformedBytesNameTheSender) {
  const std::string garbage("\xff\xff\xff\xff\x01", 5);
  const auto text = message_of<ProtocolError>([&] { decode_envelope(garbage.data(), garbage.size(), "participant 'fluid'", "the coupler"); });
  EXPECT_NE(text.find("participant 'fluid' sent a malformed message (5 bytes"), std::string::npos) << text;
}

TEST(EnvelopeCodec, VersionMismatchNamesBothVersions) {
  protocol::Envelope foreign;
  foreign.set_protocol_version(kProtocolVersion + 6);
  foreign.mutable_heartbeat()->set_wall_time(1.0);
  const std::string bytes = foreign.SerializeAsString();
  const auto text = message_of<ProtocolError>([&] { decode_envelope(bytes.data(), bytes.size(), "the coupler", "participant 'solid'"); });
  EXPECT_NE(text.find(fmt::format("the coupler speaks coupling protocol version {}, participant 'solid' speaks version {}",
                                  kProtocolVersion + 6, kProtocolVersion)),
            std::string::npos)
      << text;
}

TEST(FiniteCheck, NamesWhoFieldIndexPointAndComponent) {
  std::vector<double> values(12, 1.0);
  EXPECT_FALSE(first_non_finite(values).has_value());
  values[7] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(first_non_finite(values), std::optional<std::size_t>(7));
  const auto text = message_of<RunAborted>([&] { require_finite(values, "participant 'fluid'", "loads.forces"); });
  EXPECT_EQ(text, "participant 'fluid': non-finite value in loads.forces at index 7 (point 2, component y): nan");
  values[7] = 1.0;
  values[11] = std::numeric_limits<double>::infinity();
  EXPECT_NE(message_of<RunAborted>([&] { require_finite(values, "s", "areas", 1); }).find("index 11"), std::string::npos);
}

TEST(WireArrays, PackUnpackRoundTripAndCountCheck) {
  Eigen::Matrix3Xd points(3, 4);
  points << 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12;
  google::protobuf::RepeatedField<double> wire;
  pack_points(points, &wire, "me", "positions");
  ASSERT_EQ(wire.size(), 12);
  EXPECT_EQ(wire.Get(3), 2.0);  // x of the second point: columns travel as x, y, z triples
  EXPECT_EQ(unpack_points(wire, 4, "me", "positions"), points);
  const auto text = message_of<ProtocolError>([&] { unpack_points(wire, 5, "participant 'solid'", "motion.positions"); });
  EXPECT_NE(text.find("participant 'solid' sent motion.positions with 12 values: expected 3 per point for 5 points = 15"),
            std::string::npos)
      << text;
}

TEST(Endpoint, DefaultIsASocketInTheOutputFolderOrAShortOneInTmp) {
  EXPECT_EQ(default_endpoint("/tmp/run-a"), "ipc:///tmp/run-a/coupler.ipc");
  const std::string deep = "/tmp/" + std::string(120, 'x');
  const auto endpoint = default_endpoint(deep);
  EXPECT_EQ(endpoint.rfind("ipc:///tmp/valvefsi-", 0), 0u) << endpoint;
  EXPECT_EQ(endpoint, default_endpoint(deep));  // both sides derive the same one
  EXPECT_EQ(ipc_socket_file("ipc:///tmp/a.ipc"), std::filesystem::path("/tmp/a.ipc"));
  EXPECT_TRUE(ipc_socket_file("tcp://127.0.0.1:5555").empty());
  EXPECT_EQ(resolve_endpoint("tcp://127.0.0.1:5555", "/tmp/x"), "tcp://127.0.0.1:5555");
  ::setenv(kEndpointEnvironmentVariable, "ipc:///tmp/from-env.ipc", 1);
  EXPECT_EQ(resolve_endpoint("tcp://127.0.0.1:5555", "/tmp/x"), "ipc:///tmp/from-env.ipc");
  ::unsetenv(kEndpointEnvironmentVariable);
}

LivenessSettings fast() {
  return {std::chrono::duration<double>(0.05), std::chrono::duration<double>(0.3), std::chrono::duration<double>(0.5)};
}

std::string endpoint_in(const std::string& name) {
  return "ipc://" + (valvefsi::testing::fresh_directory(name) / "c.ipc").string();
}

protocol::Envelope finish_with(const std::string& reason) {
  protocol::Envelope envelope;
  envelope.mutable_finish()->set_reason(reason);
  return envelope;
}

TEST(MessageChannel, MessagesPassBothWaysAndHeartbeatsStayInside) {
  const auto endpoint = endpoint_in("channel-pass");
  auto router = MessageChannel::bind(endpoint, fast());
  router->expect_peer("fluid");
  auto dealer = MessageChannel::connect(endpoint, "fluid", fast());
  dealer->send("coupler", finish_with("hello"));
  std::this_thread::sleep_for(200ms);  // several heartbeats each way meanwhile
  const auto in = router->receive_from("fluid");
  EXPECT_EQ(in.finish().reason(), "hello");
  router->send("fluid", finish_with("back"));
  EXPECT_EQ(dealer->receive_from("coupler").finish().reason(), "back");
}

TEST(MessageChannel, QuietButLivePeerIsNotLost) {
  const auto endpoint = endpoint_in("channel-quiet");
  auto router = MessageChannel::bind(endpoint, fast());
  router->expect_peer("solid");
  auto dealer = MessageChannel::connect(endpoint, "solid", fast());
  protocol::Envelope hello;
  hello.mutable_handshake()->set_solver_name("quiet");
  dealer->send("coupler", hello);
  EXPECT_EQ(router->receive_from("solid").handshake().solver_name(), "quiet");
  // The dealer's owner "computes" for 4 peer timeouts: only its heartbeat thread speaks.
  EXPECT_FALSE(router->poll_any(std::chrono::duration<double>(1.2)).has_value());
  dealer->send("coupler", finish_with("done computing"));
  EXPECT_EQ(router->receive_from("solid").finish().reason(), "done computing");
}

TEST(MessageChannel, ClosedPeerIsLostWithinThePeerTimeout) {
  const auto endpoint = endpoint_in("channel-closed");
  auto router = MessageChannel::bind(endpoint, fast());
  router->expect_peer("fluid");
  auto dealer = MessageChannel::connect(endpoint, "fluid", fast());
  protocol::Envelope hello;
  hello.mutable_handshake()->set_solver_name("x");
  dealer->send("coupler", hello);
  (void)router->receive_from("fluid");
  dealer->close();
  const auto start = std::chrono::steady_clock::now();
  const auto text = message_of<PeerLost>([&] { (void)router->receive_from("fluid"); });
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_NE(text.find("participant 'fluid'"), std::string::npos) << text;
  EXPECT_LT(took, 1.0);
}

TEST(MessageChannel, ExpectedPeerThatNeverSpeaksIsLostAfterTheStartupTimeout) {
  auto router = MessageChannel::bind(endpoint_in("channel-absent"), fast());
  router->expect_peer("fluid");
  const auto text = message_of<PeerLost>([&] { (void)router->receive_any(); });
  EXPECT_NE(text.find("participant 'fluid' did not connect"), std::string::npos) << text;
}

TEST(MessageChannel, AbortFromAnyPeerEndsAWaitForAnother) {
  const auto endpoint = endpoint_in("channel-abort");
  auto router = MessageChannel::bind(endpoint, fast());
  router->expect_peer("solid");
  router->expect_peer("fluid");
  auto solid = MessageChannel::connect(endpoint, "solid", fast());
  auto fluid = MessageChannel::connect(endpoint, "fluid", fast());
  protocol::Envelope abort;
  abort.mutable_abort()->set_reason("leaflet inverted");
  solid->send("coupler", abort);
  const auto text = message_of<RunAborted>([&] { (void)router->receive_from("fluid"); });
  EXPECT_EQ(text, "participant 'solid' aborted the run: leaflet inverted");
}

TEST(MessageChannel, RejectsATimeoutShorterThanThreeHeartbeats) {
  LivenessSettings settings = fast();
  settings.peer_timeout = std::chrono::duration<double>(0.1);
  EXPECT_THROW(check_liveness_settings(settings), std::invalid_argument);
}

}  // namespace
}  // namespace valvefsi::coupling
