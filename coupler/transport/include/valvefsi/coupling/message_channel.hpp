#pragma once
// One end of the coupler <-> participant link: a ZeroMQ ROUTER in the coupler (many peers, each
// named by its routing id: "fluid", "solid") or a DEALER in a participant (one peer: "coupler").
//
// Liveness. Every side sends a Heartbeat each heartbeat_interval, also while its owner computes
// (a background thread does it), so silence means a dead or frozen process, never a long step:
// a peer that has been heard from and then stays silent longer than peer_timeout is lost; a peer
// that was expected but never spoke within startup_timeout is lost. Every receive therefore has
// a deadline that slides with the peer's heartbeats. A ROUTER send to a peer whose connection
// closed (a killed process) fails at once. Sockets use LINGER 0, so closing never blocks on a
// dead peer; close(linger) allows a short, bounded flush for goodbye messages (Finish, Abort).
//
// Thread model: the owner calls send/receive from one thread; the background thread only
// pumps the socket when the owner is not inside a call (they share it under a mutex, which is
// the memory barrier ZeroMQ asks for when a socket changes threads).

#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include <zmq.hpp>

#include "coupling.pb.h"
#include "valvefsi/coupling/transport_errors.hpp"

namespace valvefsi::coupling {

struct LivenessSettings {
  std::chrono::duration<double> heartbeat_interval{0.5};
  std::chrono::duration<double> peer_timeout{10.0};
  std::chrono::duration<double> startup_timeout{120.0};
};

// Throws std::invalid_argument unless 0 < interval and peer_timeout >= 3 intervals.
void check_liveness_settings(const LivenessSettings& settings);

struct Incoming {
  std::string peer;             // routing id of the sender ("fluid", "solid", "coupler")
  protocol::Envelope envelope;  // never a Heartbeat
};

// Called from the background thread with a fault found while the owner is busy (not inside a
// receive): a participant uses it to stop instead of finishing a long step for a dead coupler.
using FaultHandler = std::function<void(const TransportError&)>;

class MessageChannel {
 public:
  // Coupler side: binds a ROUTER at `endpoint`; `local_name` is "coupler".
  static std::unique_ptr<MessageChannel> bind(const std::string& endpoint, const LivenessSettings& liveness);
  // Participant side: a DEALER with routing id `local_name` ("fluid"/"solid") connecting to
  // `endpoint`; the coupler is expected to speak within startup_timeout.
  static std::unique_ptr<MessageChannel> connect(const std::string& endpoint, const std::string& local_name,
                                                 const LivenessSettings& liveness);
  ~MessageChannel();
  MessageChannel(const MessageChannel&) = delete;
  MessageChannel& operator=(const MessageChannel&) = delete;

  // Post: `peer` must speak within startup_timeout from now, then keep speaking.
  void expect_peer(const std::string& peer);
  // Post: `peer` is no longer watched nor sent heartbeats (it said goodbye).
  void release_peer(const std::string& peer);
  // Adopts new heartbeat/timeout settings (a participant takes the coupler's at the handshake).
  void set_liveness(const LivenessSettings& liveness);
  void set_fault_handler(FaultHandler handler);

  // Sends one message. Throws PeerLost when `peer` is not connected or cannot take the
  // message within peer_timeout. The DEALER ignores `peer` (it has one).
  void send(const std::string& peer, protocol::Envelope envelope);
  // Sends `bytes` as they are, with no envelope: only for tests that inject malformed messages.
  void send_raw_for_testing(const std::string& peer, const std::string& bytes);
  // As send, but never waits or throws: for Abort messages to peers that may be gone.
  bool try_send(const std::string& peer, protocol::Envelope envelope) noexcept;
  // Next message from `peer` (messages from other peers are kept for later). Throws PeerLost
  // when any watched peer is lost, ProtocolError for a malformed/foreign-version message,
  // RunAborted when any peer sent Abort.
  protocol::Envelope receive_from(const std::string& peer);
  // Next message from any peer; same faults.
  Incoming receive_any();
  // As receive_any but returns nothing after `wait` without a message (faults still throw).
  std::optional<Incoming> poll_any(std::chrono::duration<double> wait);

  // Tells every peer the run is over: an Abort (with `reason`) to each peer heard so far, then,
  // for up to `grace`, to each expected peer that speaks for the first time (a participant that
  // starts late must not wait out its startup timeout for a coupler that is gone). Never throws.
  void abort_all(const std::string& reason, std::chrono::duration<double> grace) noexcept;

  // Stops heartbeats and closes, allowing pending messages up to `linger` to leave.
  void close(std::chrono::milliseconds linger = std::chrono::milliseconds(0));

  [[nodiscard]] const std::string& local_name() const { return local_name_; }
  [[nodiscard]] const std::string& endpoint() const { return endpoint_; }
  // "the coupler" or "participant 'fluid'".
  [[nodiscard]] static std::string describe(const std::string& peer);

 private:
  using Clock = std::chrono::steady_clock;
  struct PeerState {
    std::optional<Clock::time_point> last_heard;
    Clock::time_point first_contact_deadline;
    bool watched = true;
    // A heartbeat could not be routed: the connection is gone. A fault only if no goodbye
    // (Finish) was still queued from it, which the next pump tells.
    std::optional<std::string> disconnected;
  };

  MessageChannel(zmq::socket_type type, std::string endpoint, std::string local_name,
                 const LivenessSettings& liveness);
  std::optional<Incoming> receive_matching(const std::string* peer, std::optional<Clock::time_point> give_up);
  void pump(std::chrono::milliseconds wait);      // caller holds mutex_
  void accept(const std::string& peer, const zmq::message_t& payload);
  void send_heartbeats_if_due(Clock::time_point now);
  void send_locked(const std::string& peer, protocol::Envelope& envelope, bool may_wait);
  // The first watched peer that is lost (silent too long, never connected, disconnected), if any.
  [[nodiscard]] std::exception_ptr find_lost_peer(Clock::time_point now) const;
  // Records a loss only if it survives one more heartbeat interval of listening; returns false
  // when that listening brought new messages (the caller should look at them first).
  bool confirm_peers_alive();
  void record_fault(std::exception_ptr fault);
  void rethrow_fault() const;
  [[nodiscard]] Clock::time_point next_wake(Clock::time_point now) const;
  void heartbeat_loop();

  bool is_router_;
  std::string endpoint_;
  std::string local_name_;
  LivenessSettings liveness_;

  std::mutex mutex_;  // guards everything below (socket included)
  zmq::context_t context_;
  zmq::socket_t socket_;
  std::map<std::string, PeerState> peers_;
  std::deque<Incoming> inbox_;
  std::exception_ptr fault_;
  FaultHandler fault_handler_;
  std::uint64_t sequence_ = 0;
  Clock::time_point next_heartbeat_;
  bool closed_ = false;

  std::mutex stop_mutex_;
  std::condition_variable stop_signal_;
  bool stop_ = false;
  std::thread heartbeat_thread_;
};

}  // namespace valvefsi::coupling
