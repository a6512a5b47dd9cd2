// Something besides the control socket and the stdin trigger that the daemon's poll loop
// (control_server.h) serves on its one thread: a button on a Linux input device
// (trigger/input_trigger.h), the systemd watchdog (systemd/watchdog_pinger.h). Because the
// watchdog is pinged from this loop, a loop that hangs stops pinging and systemd restarts us.
#pragma once

#include <chrono>
#include <optional>
#include <string>

namespace px::device {

class LoopInput {
 public:
  using TimePoint = std::chrono::steady_clock::time_point;
  virtual ~LoopInput() = default;

  // For logs: "input /dev/input/event0", "systemd watchdog".
  virtual std::string Describe() const = 0;
  // The fd to poll for reading now, or -1.
  virtual int PollFd() const = 0;
  // When the loop must call Service even without input (a reopen, a ping); nullopt: never.
  virtual std::optional<TimePoint> Deadline() const = 0;
  // Called on the loop's thread when PollFd() reported events (`revents`, from poll) or
  // Deadline() has passed (revents 0). Returns how many button presses it saw: each goes the
  // same way as a press on the socket or stdin.
  virtual int Service(TimePoint now, short revents) = 0;
};

}  // namespace px::device
