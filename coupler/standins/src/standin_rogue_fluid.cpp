// standin_rogue_fluid: a fluid that breaks the protocol on purpose, for the fault tests. It
// talks through the bare transport (not the participant library, which would refuse), then:
//   --misbehave malformed : sends bytes that are not an Envelope after receiving the surface
//   --misbehave version   : sends its handshake with protocol version 99
//   --misbehave nan       : sends an interface point cloud with a NaN in point 3
//   --misbehave order     : sends window_done where the point cloud belongs
// and then waits for the coupler's Abort, exiting with the abort's exit code.

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <limits>

#include "standin_common.hpp"
#include "valvefsi/coupling/message_channel.hpp"
#include "valvefsi/coupling/protocol_version.hpp"

int main(int argc, char** argv) {
  CLI::App app{"stand-in fluid that breaks the protocol (fault tests)"};
  valvefsi::standins::StandinSettings common;
  std::string misbehave = "malformed";
  valvefsi::standins::add_common_options(app, common);
  app.add_option("--misbehave", misbehave, "malformed | version | nan | order")
      ->check(CLI::IsMember({"malformed", "version", "nan", "order"}));
  CLI11_PARSE(app, argc, argv);
  spdlog::set_pattern("%H:%M:%S.%e %^%l%$ %v");
  namespace vc = valvefsi::coupling;
  try {
    const auto options = valvefsi::standins::participant_options(common, vc::ParticipantRole::fluid, "standin_rogue_fluid");
    auto channel = vc::MessageChannel::connect(options.endpoint, "fluid", options.liveness);
    valvefsi::protocol::Envelope hello;
    hello.mutable_handshake()->set_protocol_version(vc::kProtocolVersion);
    hello.mutable_handshake()->set_role(valvefsi::protocol::ROLE_FLUID);
    hello.mutable_handshake()->set_solver_name("standin_rogue_fluid");
    hello.mutable_handshake()->set_spatial_dimension(3);
    if (misbehave == "version") {
      hello.set_protocol_version(99);
      channel->send_raw_for_testing("coupler", hello.SerializeAsString());
    } else {
      channel->send("coupler", hello);
      (void)channel->receive_from("coupler");  // handshake_accepted
      (void)channel->receive_from("coupler");  // interface_surface
      if (misbehave == "malformed") {
        channel->send_raw_for_testing("coupler", std::string("\xff\xff\xff\xff not an envelope", 21));
      } else if (misbehave == "nan") {
        valvefsi::protocol::Envelope cloud;
        for (int i = 0; i < 12; ++i) cloud.mutable_interface_point_cloud()->add_positions(0.001 * i);
        cloud.mutable_interface_point_cloud()->set_positions(10, std::numeric_limits<double>::quiet_NaN());
        channel->send("coupler", cloud);
      } else {
        valvefsi::protocol::Envelope done;
        done.mutable_window_done()->set_max_stable_window(1.0);
        channel->send("coupler", done);
      }
    }
    for (;;) (void)channel->receive_any();  // until the coupler's Abort (or silence) ends it
  } catch (const vc::TransportError& error) {
    spdlog::error("standin_rogue_fluid: {}", error.what());
    return error.exit_code();
  } catch (const std::exception& error) {
    spdlog::error("standin_rogue_fluid: {}", error.what());
    return vc::kExitBadInput;
  }
}
