// Sends WATCHDOG=1 every half of the watchdog interval from the daemon's poll loop
// (loop_input.h): if that loop hangs, the pings stop and systemd restarts the daemon.
#pragma once

#include <chrono>
#include <functional>

#include "device/control/loop_input.h"
#include "pipeline/core/status.h"

namespace px::device {

class WatchdogPinger final : public LoopInput {
 public:
  // `ping` sends one WATCHDOG=1; the first is due at once.
  WatchdogPinger(std::chrono::microseconds watchdog_interval, std::function<Status()> ping);

  std::string Describe() const override { return "systemd watchdog"; }
  int PollFd() const override { return -1; }
  std::optional<TimePoint> Deadline() const override { return next_ping_; }
  int Service(TimePoint now, short revents) override;

  int pings() const { return pings_; }

 private:
  std::chrono::microseconds period_;
  std::function<Status()> ping_;
  TimePoint next_ping_;
  int pings_ = 0;
  bool failing_ = false;  // log a failing ping once, not every period
};

}  // namespace px::device
