// parallaxd under systemd (Type=notify, WatchdogSec=): READY=1 once the control socket listens,
// STATUS=<state> when the daemon's state changes, STOPPING=1 once on shutdown, and the watchdog
// pinger that the daemon's poll loop serves (watchdog_pinger.h). Outside systemd
// (no $NOTIFY_SOCKET) FromEnvironment returns nullptr and nothing is sent.
#pragma once

#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "device/control/loop_input.h"
#include "device/systemd/notify_socket.h"

namespace px::device {

// The watchdog interval systemd asks for: $WATCHDOG_USEC, when $WATCHDOG_PID is unset or names
// this process. nullopt without a watchdog; INVALID_ARGUMENT for a malformed value.
StatusOr<std::optional<std::chrono::microseconds>> WatchdogIntervalFromEnvironment(const char* watchdog_usec,
                                                                                   const char* watchdog_pid);

class SystemdNotifier {
 public:
  // From $NOTIFY_SOCKET, $WATCHDOG_USEC and $WATCHDOG_PID. nullptr when NOTIFY_SOCKET is unset.
  static StatusOr<std::unique_ptr<SystemdNotifier>> FromEnvironment();
  SystemdNotifier(std::unique_ptr<NotifySocket> socket, std::optional<std::chrono::microseconds> watchdog);

  // The loop input that sends WATCHDOG=1 every half interval; nullptr without a watchdog.
  std::shared_ptr<LoopInput> MakeWatchdogPinger();

  // The daemon is up: READY=1 with the current STATUS. Send failures are logged, never fatal.
  void Ready();
  // STATUS=<state> (when it changed); the first call with stopping=true also sends STOPPING=1.
  void ReportState(const std::string& state, bool stopping);
  // STOPPING=1, unless already sent.
  void Stopping();

 private:
  void Send(const std::string& message);

  std::unique_ptr<NotifySocket> socket_;
  std::optional<std::chrono::microseconds> watchdog_;
  std::mutex mutex_;
  std::string state_;  // last STATUS sent
  bool stopping_sent_ = false;
};

}  // namespace px::device
