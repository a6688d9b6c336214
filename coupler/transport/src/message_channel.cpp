#include "valvefsi/coupling/message_channel.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "valvefsi/coupling/envelope_codec.hpp"

namespace valvefsi::coupling {

namespace {

using std::chrono::duration_cast;
using std::chrono::milliseconds;

constexpr const char* kCouplerName = "coupler";
// Longest single poll, so that stop requests and new expectations are noticed promptly.
constexpr milliseconds kMaxPollSlice{200};

double seconds(std::chrono::duration<double> d) { return d.count(); }

}  // namespace

void check_liveness_settings(const LivenessSettings& settings) {
  if (!(settings.heartbeat_interval.count() > 0.0)) {
    throw std::invalid_argument(fmt::format("heartbeat interval = {} s: allowed > 0", seconds(settings.heartbeat_interval)));
  }
  if (settings.peer_timeout < 3.0 * settings.heartbeat_interval) {
    throw std::invalid_argument(fmt::format(
        "peer timeout = {} s: allowed >= 3 heartbeat intervals ({} s), or a busy but live peer looks dead",
        seconds(settings.peer_timeout), 3.0 * seconds(settings.heartbeat_interval)));
  }
  if (!(settings.startup_timeout.count() > 0.0)) {
    throw std::invalid_argument(fmt::format("startup timeout = {} s: allowed > 0", seconds(settings.startup_timeout)));
  }
}

std::unique_ptr<MessageChannel> MessageChannel::bind(const std::string& endpoint, const LivenessSettings& liveness) {
  return std::unique_ptr<MessageChannel>(new MessageChannel(zmq::socket_type::router, endpoint, kCouplerName, liveness));
}

std::unique_ptr<MessageChannel> MessageChannel::connect(const std::string& endpoint, const std::string& local_name,
                                                        const LivenessSettings& liveness) {
  auto channel = std::unique_ptr<MessageChannel>(
      new MessageChannel(zmq::socket_type::dealer, endpoint, local_name, liveness));
  channel->expect_peer(kCouplerName);
  return channel;
}

MessageChannel::MessageChannel(zmq::socket_type type, std::string endpoint, std::string local_name,
                               const LivenessSettings& liveness)
    : is_router_(type == zmq::socket_type::router),
      endpoint_(std::move(endpoint)),
      local_name_(std::move(local_name)),
      liveness_(liveness),
      context_(1),
      socket_(context_, type) {
  check_liveness_settings(liveness_);
  socket_.set(zmq::sockopt::linger, 0);
  const auto send_timeout = duration_cast<milliseconds>(liveness_.peer_timeout);
  socket_.set(zmq::sockopt::sndtimeo, static_cast<int>(send_timeout.count()));
  try {
    if (is_router_) {
      // Sending to a peer whose connection is gone fails (EHOSTUNREACH) instead of vanishing.
      socket_.set(zmq::sockopt::router_mandatory, 1);
      socket_.bind(endpoint_);
    } else {
      socket_.set(zmq::sockopt::routing_id, local_name_);
      socket_.connect(endpoint_);
    }
  } catch (const zmq::error_t& e) {
    throw PeerLost(fmt::format("{}: cannot {} endpoint '{}': {}", local_name_, is_router_ ? "bind" : "connect to",
                               endpoint_, e.what()));
  }
  next_heartbeat_ = Clock::now();
  heartbeat_thread_ = std::thread([this] { heartbeat_loop(); });
}

MessageChannel::~MessageChannel() { close(); }

void MessageChannel::close(milliseconds linger) {
  {
    std::lock_guard stop_lock(stop_mutex_);
    stop_ = true;
  }
  stop_signal_.notify_all();
  if (heartbeat_thread_.joinable()) heartbeat_thread_.join();
  std::lock_guard lock(mutex_);
  if (closed_) return;
  closed_ = true;
  socket_.set(zmq::sockopt::linger, static_cast<int>(linger.count()));
  socket_.close();
  context_.close();  // returns once pending messages left or `linger` passed
}

std::string MessageChannel::describe(const std::string& peer) {
  return peer == kCouplerName ? std::string("the coupler") : fmt::format("participant '{}'", peer);
}

void MessageChannel::expect_peer(const std::string& peer) {
  std::lock_guard lock(mutex_);
  auto& state = peers_[peer];
  state.watched = true;
  state.first_contact_deadline =
      Clock::now() + duration_cast<Clock::duration>(liveness_.startup_timeout);
}

void MessageChannel::release_peer(const std::string& peer) {
  std::lock_guard lock(mutex_);
  if (auto it = peers_.find(peer); it != peers_.end()) it->second.watched = false;
}

void MessageChannel::set_liveness(const LivenessSettings& liveness) {
  check_liveness_settings(liveness);
  std::lock_guard lock(mutex_);
  liveness_ = liveness;
  socket_.set(zmq::sockopt::sndtimeo,
              static_cast<int>(duration_cast<milliseconds>(liveness_.peer_timeout).count()));
}

void MessageChannel::set_fault_handler(FaultHandler handler) {
  std::lock_guard lock(mutex_);
  fault_handler_ = std::move(handler);
}

void MessageChannel::send(const std::string& peer, protocol::Envelope envelope) {
  std::lock_guard lock(mutex_);
  if (closed_) throw PeerLost(fmt::format("{}: channel already closed", local_name_));
  send_locked(peer, envelope, true);
}

void MessageChannel::send_locked(const std::string& peer, protocol::Envelope& envelope, bool may_wait) {
  const std::size_t size = stamp_envelope(envelope, sequence_++);
  zmq::message_t payload(size);
  encode_envelope_into(envelope, payload.data(), size);
  const auto flags = may_wait ? zmq::send_flags::none : zmq::send_flags::dontwait;
  const std::string target = is_router_ ? peer : std::string(kCouplerName);
  try {
    if (is_router_) {
      if (!socket_.send(zmq::buffer(peer), flags | zmq::send_flags::sndmore)) {
        if (may_wait) throw PeerLost(fmt::format("{} did not take a message within {} s: it is frozen or overloaded",
                                                 describe(target), seconds(liveness_.peer_timeout)));
        return;  // a heartbeat that does not fit is simply skipped
      }
    }
    if (!socket_.send(payload, flags)) {
      if (may_wait) throw PeerLost(fmt::format("{} did not take a message within {} s: it is frozen or overloaded",
                                               describe(target), seconds(liveness_.peer_timeout)));
    }
  } catch (const zmq::error_t& e) {
    if (e.num() == EHOSTUNREACH) {
      throw PeerLost(fmt::format("{} is not connected to {} (its process ended or closed the connection)",
                                 describe(target), endpoint_));
    }
    throw PeerLost(fmt::format("{}: sending '{}' to {} failed: {}", local_name_, body_name(envelope),
                               describe(target), e.what()));
  }
}

void MessageChannel::send_raw_for_testing(const std::string& peer, const std::string& bytes) {
  std::lock_guard lock(mutex_);
  if (is_router_) socket_.send(zmq::buffer(peer), zmq::send_flags::sndmore);
  socket_.send(zmq::buffer(bytes), zmq::send_flags::none);
}

void MessageChannel::abort_all(const std::string& reason, std::chrono::duration<double> grace) noexcept {
  try {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    std::map<std::string, bool> told;
    const auto give_up = Clock::now() + duration_cast<Clock::duration>(grace);
    for (;;) {
      bool waiting_for_someone = false;
      for (const auto& [name, state] : peers_) {
        if (state.last_heard && !told[name]) {
          protocol::Envelope abort;
          abort.mutable_abort()->set_reason(reason);
          abort.mutable_abort()->set_origin(is_router_ ? protocol::ROLE_COUPLER : protocol::ROLE_UNSPECIFIED);
          try {
            send_locked(name, abort, false);
          } catch (const TransportError&) {
            // gone already
          }
          told[name] = true;
        }
        if (!state.last_heard && state.watched) waiting_for_someone = true;
      }
      if (!waiting_for_someone || Clock::now() >= give_up) return;
      pump(milliseconds(20));
    }
  } catch (...) {
    // Best effort: the run is ending anyway.
  }
}

bool MessageChannel::try_send(const std::string& peer, protocol::Envelope envelope) noexcept {
  try {
    std::lock_guard lock(mutex_);
    if (closed_) return false;
    send_locked(peer, envelope, false);
    return true;
  } catch (...) {
    return false;
  }
}

protocol::Envelope MessageChannel::receive_from(const std::string& peer) {
  return receive_matching(&peer, std::nullopt)->envelope;
}

Incoming MessageChannel::receive_any() { return *receive_matching(nullptr, std::nullopt); }

std::optional<Incoming> MessageChannel::poll_any(std::chrono::duration<double> wait) {
  return receive_matching(nullptr, Clock::now() + duration_cast<Clock::duration>(wait));
}

std::optional<Incoming> MessageChannel::receive_matching(const std::string* peer,
                                                         std::optional<Clock::time_point> give_up) {
  std::lock_guard lock(mutex_);
  if (closed_) throw PeerLost(fmt::format("{}: channel already closed", local_name_));
  for (;;) {
    rethrow_fault();
    // An Abort from anyone ends the wait, whoever we were waiting for.
    for (const auto& item : inbox_) {
      if (item.envelope.has_abort()) {
        const auto& abort = item.envelope.abort();
        throw RunAborted(fmt::format("{} aborted the run: {}", describe(item.peer), abort.reason()));
      }
    }
    const auto match = std::find_if(inbox_.begin(), inbox_.end(),
                                    [&](const Incoming& item) { return peer == nullptr || item.peer == *peer; });
    if (match != inbox_.end()) {
      Incoming found = std::move(*match);
      inbox_.erase(match);
      return found;
    }
    const auto now = Clock::now();
    if (give_up && now >= *give_up) return std::nullopt;
    if (!confirm_peers_alive()) continue;  // it drained new messages: look at them first
    rethrow_fault();
    auto wake = next_wake(now);
    if (give_up) wake = std::min(wake, *give_up);
    pump(std::clamp(duration_cast<milliseconds>(wake - now) + milliseconds(1), milliseconds(0), kMaxPollSlice));
  }
}

void MessageChannel::pump(milliseconds wait) {
  send_heartbeats_if_due(Clock::now());
  zmq::pollitem_t item{socket_.handle(), 0, ZMQ_POLLIN, 0};
  zmq::poll(&item, 1, wait);
  send_heartbeats_if_due(Clock::now());  // due during a long poll; the drain below follows it
  for (;;) {
    zmq::message_t first;
    if (!socket_.recv(first, zmq::recv_flags::dontwait)) break;
    std::string peer = is_router_ ? first.to_string() : std::string(kCouplerName);
    zmq::message_t payload;
    if (is_router_) {
      if (!first.more()) {
        record_fault(std::make_exception_ptr(ProtocolError(
            fmt::format("{} sent an empty message (no payload frame)", describe(peer)))));
        continue;
      }
      (void)socket_.recv(payload, zmq::recv_flags::none);
    } else {
      payload = std::move(first);
    }
    while (payload.more()) {  // extra frames are not part of the protocol: keep the last one
      zmq::message_t extra;
      (void)socket_.recv(extra, zmq::recv_flags::none);
      payload = std::move(extra);
    }
    accept(peer, payload);
  }
  // No heartbeat after the drain: a connection found gone while sending must be followed by a
  // drain, so that a goodbye it sent just before closing is read before it counts as lost.
}

void MessageChannel::accept(const std::string& peer, const zmq::message_t& payload) {
  const auto now = Clock::now();
  auto [it, is_new] = peers_.try_emplace(peer);
  if (is_new) it->second.watched = false;  // not expected: its messages are delivered, its silence is not watched
  it->second.last_heard = now;
  try {
    auto envelope = decode_envelope(payload.data(), payload.size(), describe(peer), describe(local_name_));
    if (envelope.has_heartbeat()) return;
    if (envelope.has_finish()) it->second.watched = false;  // a goodbye: its silence from now on is expected
    inbox_.push_back(Incoming{peer, std::move(envelope)});
  } catch (const ProtocolError&) {
    record_fault(std::current_exception());
  }
}

void MessageChannel::send_heartbeats_if_due(Clock::time_point now) {
  if (now < next_heartbeat_) return;
  next_heartbeat_ = now + duration_cast<Clock::duration>(liveness_.heartbeat_interval);
  const double wall = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  for (auto& [name, state] : peers_) {
    // A ROUTER can only reach peers it heard and stops at their goodbye; a DEALER keeps its
    // coupler informed until it closes (it may write output for a while after Finish).
    if (is_router_ && (!state.watched || !state.last_heard || state.disconnected)) continue;
    protocol::Envelope heartbeat;
    heartbeat.mutable_heartbeat()->set_wall_time(wall);
    try {
      send_locked(name, heartbeat, false);
    } catch (const PeerLost& lost) {
      state.disconnected = lost.what();
    }
  }
}

bool MessageChannel::confirm_peers_alive() {
  if (!find_lost_peer(Clock::now())) return true;
  // Judge only after listening: if this process itself was descheduled or busy, the peer's
  // heartbeats may be waiting unread. A live peer speaks within one heartbeat interval.
  const std::size_t before = inbox_.size();
  pump(std::clamp(duration_cast<milliseconds>(liveness_.heartbeat_interval), milliseconds(10), kMaxPollSlice));
  if (inbox_.size() != before) return false;
  if (auto lost = find_lost_peer(Clock::now())) record_fault(lost);
  return true;
}

std::exception_ptr MessageChannel::find_lost_peer(Clock::time_point now) const {
  for (const auto& [name, state] : peers_) {
    if (!state.watched) continue;
    if (state.disconnected) {
      return std::make_exception_ptr(PeerLost(*state.disconnected));
    } else if (state.last_heard) {
      const std::chrono::duration<double> silence = now - *state.last_heard;
      if (silence > liveness_.peer_timeout) {
        return std::make_exception_ptr(PeerLost(fmt::format(
            "{} has been silent for {:.1f} s (peer timeout {} s, heartbeat every {} s): it died or is frozen",
            describe(name), silence.count(), seconds(liveness_.peer_timeout),
            seconds(liveness_.heartbeat_interval))));
      }
    } else if (now > state.first_contact_deadline) {
      return std::make_exception_ptr(PeerLost(fmt::format(
          "{} did not connect to {} within the startup timeout of {} s", describe(name), endpoint_,
          seconds(liveness_.startup_timeout))));
    }
  }
  return nullptr;
}

void MessageChannel::record_fault(std::exception_ptr fault) {
  if (!fault_) fault_ = std::move(fault);  // the first fault is the cause; later ones follow from it
}

void MessageChannel::rethrow_fault() const {
  if (fault_) std::rethrow_exception(fault_);
}

MessageChannel::Clock::time_point MessageChannel::next_wake(Clock::time_point now) const {
  auto wake = next_heartbeat_;
  for (const auto& [name, state] : peers_) {
    if (!state.watched) continue;
    const auto expiry = state.last_heard
                            ? *state.last_heard + duration_cast<Clock::duration>(liveness_.peer_timeout)
                            : state.first_contact_deadline;
    wake = std::min(wake, expiry);
  }
  return std::max(wake, now);
}

void MessageChannel::heartbeat_loop() {
  for (;;) {
    milliseconds period;
    {
      std::lock_guard lock(mutex_);
      period = std::max(milliseconds(1), duration_cast<milliseconds>(liveness_.heartbeat_interval / 4));
    }
    {
      std::unique_lock stop_lock(stop_mutex_);
      if (stop_signal_.wait_for(stop_lock, period, [this] { return stop_; })) return;
    }
    std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock() || closed_) continue;  // the owner is inside a call and pumps itself
    pump(milliseconds(0));
    (void)confirm_peers_alive();
    if (fault_ && fault_handler_) {
      const auto fault = fault_;
      const auto handler = fault_handler_;
      fault_handler_ = nullptr;  // tell once
      lock.unlock();
      try {
        std::rethrow_exception(fault);
      } catch (const TransportError& error) {
        handler(error);
      }
    }
  }
}

}  // namespace valvefsi::coupling
