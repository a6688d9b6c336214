#include "valvefsi/coupler/coupler_run.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <optional>

#include "valvefsi/coupler/coupling_schemes.hpp"
#include "valvefsi/coupler/interface_session.hpp"
#include "valvefsi/coupler/series_writer.hpp"
#include "valvefsi/coupler/window_exchange.hpp"
#include "valvefsi/coupling/endpoint.hpp"
#include "valvefsi/coupling/envelope_codec.hpp"
#include "valvefsi/coupling/message_channel.hpp"

namespace valvefsi::coupler {

namespace {

using coupling::MessageChannel;

// Time given to goodbye messages (Finish, Abort) to leave before the socket closes.
constexpr std::chrono::milliseconds kGoodbyeLinger{500};

std::vector<SeriesColumn> series_columns() {
  return {
      {"time", 1, "s", "end of the coupling window"},
      {"window_size", 1, "s", "length of the window"},
      {"window_index", 1, "", "0, 1, 2, ..."},
      {"iterations", 1, "", "coupling iterations in the window (1 for explicit schemes)"},
      {"relative_residual", 1, "", "implicit schemes: |x - x~| / |x| of the solid's end displacement at the last iteration"},
      {"force_fluid", 3, "N", "total force the fluid returned, summed over its interface points"},
      {"force_solid", 3, "N", "total force applied to the solid, summed over its interface nodes"},
      {"power_fluid", 1, "W", "sum of force . velocity at the fluid's points"},
      {"power_solid", 1, "W", "sum of force . velocity at the solid's nodes"},
      {"interface_oscillation", 1, "m/s",
       "largest solid interface node's RMS velocity jump between windows (v_n - 2 v_n-1 + v_n-2) over the last "
       "complete block of 16 windows (coupling.runaway_oscillation_speed)"},
      {"load_work_solid", 1, "J",
       "sum of force . (x_end - x_start) at the solid's nodes: the loads' work on the solid over the window"},
  };
}

std::array<double, 15> series_row(const WindowRecord& r) {
  return {r.time_end,        r.size,           static_cast<double>(r.index), static_cast<double>(r.iterations),
          r.relative_residual, r.force_fluid.x(), r.force_fluid.y(),          r.force_fluid.z(),
          r.force_solid.x(), r.force_solid.y(), r.force_solid.z(),          r.power_fluid,
          r.power_solid,     r.interface_oscillation, r.load_work_solid};
}

void finish_run(MessageChannel& channel, double end_time) {
  for (const char* peer : {kFluid, kSolid}) {
    protocol::Envelope finish;
    finish.mutable_finish()->set_reason(fmt::format("end time {} s reached", end_time));
    channel.send(peer, std::move(finish));
  }
  for (const char* peer : {kFluid, kSolid}) {
    const auto answer = channel.receive_from(peer);
    if (!answer.has_finish()) {
      throw coupling::ProtocolError(fmt::format("{} answered the coupler's finish with '{}' instead of 'finish'",
                                                MessageChannel::describe(peer), coupling::body_name(answer)));
    }
    channel.release_peer(peer);
  }
}

// A participant that has not connected yet gets this long to show up and hear the abort.
constexpr double kAbortGraceSeconds = 3.0;

void abort_participants(MessageChannel& channel, const std::string& reason, const CouplerSettings& settings) {
  channel.abort_all(reason, std::chrono::duration<double>(std::min(kAbortGraceSeconds, settings.liveness.startup_timeout.count())));
}

}  // namespace

int run_coupler(const CouplerSettings& settings) {
  std::unique_ptr<MessageChannel> channel;
  try {
    channel = MessageChannel::bind(settings.endpoint, settings.liveness);
  } catch (const coupling::TransportError& error) {
    spdlog::error("coupler: {}", error.what());
    return error.exit_code();
  }
  spdlog::info("coupler: listening on {} ({}, window {} s, end {} s)", settings.endpoint, scheme_label(settings),
               settings.window_size, settings.end_time);
  channel->expect_peer(kFluid);
  channel->expect_peer(kSolid);
  int exit_code = coupling::kExitOk;
  try {
    const InterfaceSession session = open_session(*channel, settings);
    SeriesWriter series(settings.series_file, series_columns(), settings.series_flush_rows);
    WindowExchange exchange(*channel, session);
    const auto summary = run_coupling_scheme(exchange, settings, [&](const WindowRecord& record) {
      const auto row = series_row(record);
      series.append(row);
    });
    series.flush();
    finish_run(*channel, summary.final_time);
    spdlog::info("coupler: done: {} windows to t = {} s, {} coupling iterations, {} windows not converged; series in {}",
                 summary.windows, summary.final_time, summary.total_iterations, summary.unconverged_windows,
                 settings.series_file.string());
  } catch (const coupling::TransportError& error) {
    spdlog::error("coupler: {}; stopping the run", error.what());
    abort_participants(*channel, error.what(), settings);
    exit_code = error.exit_code();
  } catch (const std::exception& error) {
    spdlog::error("coupler: {}; stopping the run", error.what());
    abort_participants(*channel, fmt::format("the coupler failed: {}", error.what()), settings);
    exit_code = coupling::kExitBadInput;
  }
  channel->close(kGoodbyeLinger);
  // The socket file of an ipc:// endpoint is ours; leave nothing behind in the output folder.
  if (const auto socket_file = coupling::ipc_socket_file(settings.endpoint); !socket_file.empty()) {
    std::error_code ignored;
    std::filesystem::remove(socket_file, ignored);
  }
  return exit_code;
}

}  // namespace valvefsi::coupler
