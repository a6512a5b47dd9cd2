#include "device/systemd/watchdog_pinger.h"

#include "pipeline/core/log.h"

namespace px::device {

WatchdogPinger::WatchdogPinger(std::chrono::microseconds watchdog_interval, std::function<Status()> ping)
    : period_(std::max(watchdog_interval / 2, std::chrono::microseconds(1000))),
      ping_(std::move(ping)),
      next_ping_(std::chrono::steady_clock::now()) {}

int WatchdogPinger::Service(TimePoint now, short) {
  if (now < next_ping_) return 0;
  Status sent = ping_();
  if (!sent.ok() && !failing_) Logger("device")->warn("watchdog ping failed: {}", sent.ToString());
  failing_ = !sent.ok();
  pings_++;
  // From now, not from the missed deadline: a loop that stalled must not burst pings to catch up.
  next_ping_ = now + period_;
  return 0;
}

}  // namespace px::device
