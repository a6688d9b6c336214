// Time of one serial-explicit coupling window through the real coupler code: motion mapped and
// sent to the fluid, loads back, mapped conservatively and sent to the solid, motion back --
// four messages through ZeroMQ (ipc or tcp) between three parties in three threads of one
// process (the participants answer at once, so this is pure coupling overhead). Next to it: a
// plain memcpy of the same 18 doubles per point the window moves.
//   bench_coupling_window --benchmark_min_time=1

#include <benchmark/benchmark.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <thread>
#include <unistd.h>
#include <vector>

#include "valvefsi/coupler/interface_session.hpp"
#include "valvefsi/coupler/window_exchange.hpp"
#include "valvefsi/coupling/message_channel.hpp"
#include "valvefsi/coupling/participant.hpp"

namespace {

using namespace valvefsi;

// A flat plate of about `points` nodes, triangulated; the fluid's points are its nodes.
coupling::InterfaceSurfaceData plate(int points) {
  const int nx = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(points))));
  const int ny = (points + nx - 1) / nx;
  coupling::InterfaceSurfaceData s;
  s.positions.resize(3, nx * ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) s.positions.col(j * nx + i) << 1e-3 * i, 1e-3 * j, 0.0;
  s.cells.resize(3, 2 * (nx - 1) * (ny - 1));
  int c = 0;
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = j * nx + i;
      s.cells.col(c++) << a, a + 1, a + nx + 1;
      s.cells.col(c++) << a, a + nx + 1, a + nx;
    }
  s.node_areas = Eigen::VectorXd::Constant(nx * ny, 1e-6);
  return s;
}

std::string endpoint_for(bool tcp, int points) {
  static std::atomic<int> counter{0};
  const int n = counter++;
  if (tcp) return "tcp://127.0.0.1:" + std::to_string(47100 + n);
  return "ipc:///tmp/vfsi-bench-" + std::to_string(::getpid()) + "-" + std::to_string(points) + "-" + std::to_string(n) + ".ipc";
}

void BM_CouplingWindow(benchmark::State& state) {
  const int points = static_cast<int>(state.range(0));
  const bool tcp = state.range(1) == 1;
  const auto surface = plate(points);
  const std::string endpoint = endpoint_for(tcp, points);

  coupler::CouplerSettings settings;
  settings.endpoint = endpoint;
  auto channel = coupling::MessageChannel::bind(endpoint, settings.liveness);
  channel->expect_peer(coupler::kFluid);
  channel->expect_peer(coupler::kSolid);

  auto participant_options = [&](coupling::ParticipantRole role) {
    coupling::ParticipantOptions o;
    o.role = role;
    o.solver_name = "bench";
    o.endpoint = endpoint;
    return o;
  };
  std::thread solid([&] {
    coupling::Participant p(participant_options(coupling::ParticipantRole::solid));
    coupling::InterfaceMotion motion{surface.positions, Eigen::Matrix3Xd::Zero(3, surface.positions.cols())};
    p.initialize_solid(surface, motion);
    coupling::Window w;
    while (p.next_window(w)) p.complete_window(motion, 0.0);
    p.finalize();
  });
  std::thread fluid([&] {
    coupling::Participant p(participant_options(coupling::ParticipantRole::fluid));
    p.initialize_fluid([](const coupling::InterfaceSurfaceData& s) {
      return coupling::InterfacePoints{s.positions, s.node_areas};
    });
    coupling::InterfaceLoads loads{Eigen::Matrix3Xd::Constant(3, p.interface_size(), 1e-3)};
    coupling::Window w;
    while (p.next_window(w)) p.complete_window(loads, 0.0);
    p.finalize();
  });

  const coupler::InterfaceSession session = coupler::open_session(*channel, settings);
  coupler::WindowExchange exchange(*channel, session);
  coupler::SolidState solid_state{session.solid_initial_positions, session.solid_initial_velocities};
  coupler::WindowSpan window{0.0, 1e-5, 0, 0};
  for (auto _ : state) {
    exchange.send_motion_to_fluid(window, solid_state.positions, solid_state.velocities);
    const auto reply = exchange.receive_fluid();
    exchange.send_loads_to_solid(window, exchange.loads_to_nodes(reply.forces));
    benchmark::DoNotOptimize(exchange.receive_solid());
    window.time += window.size;
    ++window.index;
  }
  for (const char* peer : {coupler::kFluid, coupler::kSolid}) {
    protocol::Envelope finish;
    finish.mutable_finish()->set_reason("benchmark done");
    channel->send(peer, finish);
  }
  for (const char* peer : {coupler::kFluid, coupler::kSolid}) (void)channel->receive_from(peer);
  solid.join();
  fluid.join();
  state.counters["points"] = static_cast<double>(surface.positions.cols());
  state.counters["MB_per_window"] = 18.0 * 8.0 * static_cast<double>(surface.positions.cols()) / 1e6;
  state.SetLabel(tcp ? "tcp" : "ipc");
}

void BM_MemcpySameData(benchmark::State& state) {
  const std::size_t doubles = 18 * static_cast<std::size_t>(state.range(0));
  std::vector<double> from(doubles, 1.0), to(doubles);
  for (auto _ : state) {
    std::memcpy(to.data(), from.data(), doubles * sizeof(double));
    benchmark::ClobberMemory();
  }
  state.counters["points"] = static_cast<double>(state.range(0));
}

BENCHMARK(BM_CouplingWindow)
    ->ArgsProduct({{1000, 10000, 100000}, {0, 1}})
    ->ArgNames({"points", "tcp"})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK(BM_MemcpySameData)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  spdlog::set_level(spdlog::level::warn);  // the participants' start-up lines would drown the table
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
