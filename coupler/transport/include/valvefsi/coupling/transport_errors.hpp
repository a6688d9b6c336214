#pragma once
// The ways a coupled run can fail on the wire. what() is a complete message for the user that
// names the peer and the cause; the exit code tells scripts which kind it was.

#include <stdexcept>
#include <string>

namespace valvefsi::coupling {

// Process exit codes shared by the coupler, the participants and the launcher.
enum ExitCode : int {
  kExitOk = 0,
  kExitBadInput = 2,       // a case file, command line or interface that cannot be used
  kExitPeerLost = 3,       // a peer went silent (died, froze) or disconnected
  kExitProtocolError = 4,  // a malformed message, a version mismatch, an out-of-order message
  kExitAborted = 5,        // a peer aborted the run, or a non-finite value was exchanged
  kExitCouplingFailed = 6,  // the coupled solution failed a check: a diverged implicit window,
                            // an interface running away
};

class TransportError : public std::runtime_error {
 public:
  TransportError(const std::string& message, int exit_code)
      : std::runtime_error(message), exit_code_(exit_code) {}
  [[nodiscard]] int exit_code() const { return exit_code_; }

 private:
  int exit_code_;
};

// A peer did not speak for longer than the peer timeout, never connected, or disconnected.
class PeerLost : public TransportError {
 public:
  explicit PeerLost(const std::string& message) : TransportError(message, kExitPeerLost) {}
};

// Bytes that are not an Envelope, a protocol version other than ours, or a message that the
// protocol does not allow at this point.
class ProtocolError : public TransportError {
 public:
  explicit ProtocolError(const std::string& message) : TransportError(message, kExitProtocolError) {}
};

// A peer sent Abort, or data that cannot be used (NaN); the run stops.
class RunAborted : public TransportError {
 public:
  explicit RunAborted(const std::string& message) : TransportError(message, kExitAborted) {}
};

// The coupler stops a run whose coupled solution fails a check (the message names the window,
// the quantity and what to change); the participants hear it as an abort.
class CouplingFailed : public TransportError {
 public:
  explicit CouplingFailed(const std::string& message) : TransportError(message, kExitCouplingFailed) {}
};

}  // namespace valvefsi::coupling
