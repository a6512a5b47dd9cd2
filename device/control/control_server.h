// The daemon's event loop for its two trigger inputs: a Unix domain socket speaking JSON lines
// (control_protocol.h) and, optionally, a file descriptor (stdin) where each line is one press.
// One thread polls everything; replies may come later from any thread (a "wait" is answered
// when its job finishes), and each connection gets its replies in request order.
// Security (README "Security of the control socket"): the socket file is 0600, or 0660 for a
// configured group; every connection's peer is checked (peer_access.h) and others are refused
// with a logged reason; request lines are limited to kMaxControlLineBytes; at most
// kMaxControlConnections are open at once; a client that does not read its replies gets no
// further requests served (its unsent replies never pile up).
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "device/control/loop_input.h"
#include "device/control/peer_access.h"
#include "pipeline/core/status.h"

namespace px::device {

class ControlServer {
 public:
  // Sends one reply line (without newline) to the connection that made the request. Thread-safe;
  // call exactly once per request. A reply for a connection that has gone is dropped.
  using Respond = std::function<void(const std::string& reply)>;
  using RequestHandler = std::function<void(const std::string& line, Respond respond)>;
  using TriggerHandler = std::function<void(const std::string& line)>;
  using EofHandler = std::function<void()>;

  struct Options {
    std::filesystem::path socket_path;  // empty: no socket
    int trigger_fd = -1;                // each line read is a press; -1: none. Not closed by us.
    // Served on the loop thread too (input-device buttons, the systemd watchdog); each press
    // they report goes to on_trigger with the input's description as the line.
    std::vector<std::shared_ptr<LoopInput>> inputs;
    // Who may connect; the socket file gets the matching mode (and group).
    ControlAccess access = OwnerAccess();
  };
  struct Handlers {
    RequestHandler on_request;  // a request line from the socket
    TriggerHandler on_trigger;  // a line from trigger_fd, or a press from one of `inputs`
    EofHandler on_trigger_eof;  // trigger_fd reached end of file (or failed)
  };

  // Binds the socket (creating its folder; replacing a stale socket file, refusing when another
  // process is listening there: ALREADY_EXISTS), restricts the file to options.access before it
  // listens (PERMISSION_DENIED when the group cannot be set). Nothing is read until Start.
  static StatusOr<std::unique_ptr<ControlServer>> Open(const Options& options, Handlers handlers);
  ~ControlServer();  // Stop(), then closes and unlinks the socket

  void Start();  // runs the loop on its own thread
  // Sends what replies are ready, then ends the loop and joins it. Idempotent, thread-safe,
  // but never from inside a handler.
  void Stop();

 private:
  struct Shared;
  struct Connection;
  struct LoopState;  // the loop thread's connections and trigger input (control_server.cc)
  struct PollSet;    // what one poll() waits on, and where each kind of fd sits in it
  ControlServer(const Options& options, Handlers handlers, int listen_fd, int wake_read, int wake_write);
  // The loop, one round: replies out, requests dispatched, finished connections closed, then
  // one poll() and its events: new connections, trigger lines, loop inputs, connection input.
  void Loop();
  void DeliverReplies(LoopState& state);
  void DispatchRequests(LoopState& state);
  PollSet BuildPollSet(LoopState& state) const;
  void AcceptConnections(LoopState& state);
  void ReadTrigger(LoopState& state);
  void ServiceLoopInputs(const PollSet& poll_set);

  Options options_;
  Handlers handlers_;
  int listen_fd_ = -1;
  int wake_read_ = -1;
  std::shared_ptr<Shared> shared_;  // mailbox for replies; outlives us while Respond closures live
  std::thread thread_;
  std::mutex stop_mutex_;
  bool stopped_ = false;
};

}  // namespace px::device
