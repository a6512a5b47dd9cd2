// The one-button trigger on a Linux input event device (evdev, /dev/input/eventN): a press is an
// EV_KEY event for the configured key with value 1; autorepeat (2), release (0) and other keys
// are ignored, and a press within `debounce` of the last accepted one (kernel timestamps) is
// contact bounce. A device that vanishes (ENODEV, end of file) is closed, logged and reopened
// every `retry` until it is back; the daemon stays up. Runs inside the daemon's poll loop
// (loop_input.h), so a press becomes a job exactly as a "capture" on the socket does.
#pragma once

#include <linux/input.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "device/control/loop_input.h"

namespace px::device {

struct InputTriggerOptions {
  std::filesystem::path device;  // e.g. /dev/input/event0 or /dev/input/by-id/...-event-kbd
  int key_code = KEY_CAMERA;
  std::chrono::milliseconds debounce{50};
  std::chrono::milliseconds retry{2000};  // reopen interval while the device is missing
};

class InputTrigger final : public LoopInput {
 public:
  // Does not open yet: the loop's first Service does (Deadline() is due at once).
  explicit InputTrigger(InputTriggerOptions options);
  ~InputTrigger() override;
  InputTrigger(const InputTrigger&) = delete;
  InputTrigger& operator=(const InputTrigger&) = delete;

  std::string Describe() const override;
  int PollFd() const override { return fd_; }
  std::optional<TimePoint> Deadline() const override;
  int Service(TimePoint now, short revents) override;

  struct Stats {
    int presses = 0;      // accepted
    int bounces = 0;      // presses dropped by the debounce
    int repeats = 0;      // autorepeat events ignored
    int opens = 0;        // successful opens (1 + reconnects)
    int disconnects = 0;  // times the device went away
  };
  const Stats& stats() const { return stats_; }
  bool connected() const { return fd_ >= 0; }

 private:
  void TryOpen(TimePoint now);
  void Disconnect(const std::string& why, TimePoint now);
  int ReadEvents(TimePoint now);
  bool HandleEvent(const input_event& event);  // true for an accepted press

  InputTriggerOptions options_;
  int fd_ = -1;
  TimePoint next_open_{};        // when to try opening again while fd_ < 0
  std::string last_open_error_;  // to log a failing open once, not every retry
  std::string pending_;          // bytes of a partly read event
  std::optional<int64_t> last_press_us_;
  Stats stats_;
};

}  // namespace px::device
