#include "device/trigger/input_trigger.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "device/trigger/key_codes.h"
#include "pipeline/core/log.h"

namespace px::device {
namespace {

int64_t EventTimeUs(const input_event& event) {
  return static_cast<int64_t>(event.input_event_sec) * 1'000'000 + static_cast<int64_t>(event.input_event_usec);
}

// Whether an evdev node can send `code`; nullopt when the fd is not an evdev node (a FIFO in tests).
std::optional<bool> DeviceHasKey(int fd, int code) {
  uint8_t bits[KEY_MAX / 8 + 1] = {};
  if (::ioctl(fd, EVIOCGBIT(EV_KEY, sizeof(bits)), bits) < 0) return std::nullopt;
  return (bits[code / 8] >> (code % 8)) & 1;
}

}  // namespace

InputTrigger::InputTrigger(InputTriggerOptions options) : options_(std::move(options)) {}

InputTrigger::~InputTrigger() {
  if (fd_ >= 0) ::close(fd_);
}

std::string InputTrigger::Describe() const {
  return "input " + options_.device.string() + " " + KeyCodeName(options_.key_code);
}

std::optional<LoopInput::TimePoint> InputTrigger::Deadline() const {
  if (fd_ >= 0) return std::nullopt;
  return next_open_;
}

int InputTrigger::Service(TimePoint now, short revents) {
  if (fd_ < 0) {
    if (now >= next_open_) TryOpen(now);
    return 0;
  }
  if (revents == 0) return 0;
  return ReadEvents(now);
}

void InputTrigger::TryOpen(TimePoint now) {
  auto log = Logger("trigger");
  int fd = ::open(options_.device.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    const std::string error = std::strerror(errno);
    if (error != last_open_error_) {
      log->warn("cannot open trigger device {}: {}; retrying every {} ms",
                options_.device.string(),
                error,
                options_.retry.count());
    }
    last_open_error_ = error;
    next_open_ = now + options_.retry;
    return;
  }
  fd_ = fd;
  last_open_error_.clear();
  pending_.clear();
  stats_.opens++;
  const std::optional<bool> has_key = DeviceHasKey(fd_, options_.key_code);
  if (has_key == false) {
    log->warn("trigger device {} does not report {}; presses of other keys are ignored",
              options_.device.string(),
              KeyCodeName(options_.key_code));
  }
  log->info("trigger: listening on {} for {} (code {}, debounce {} ms){}",
            options_.device.string(),
            KeyCodeName(options_.key_code),
            options_.key_code,
            options_.debounce.count(),
            stats_.opens > 1 ? " again" : "");
}

void InputTrigger::Disconnect(const std::string& why, TimePoint now) {
  Logger("trigger")->warn(
      "trigger device {} went away ({}); reopening every {} ms", options_.device.string(), why, options_.retry.count());
  ::close(fd_);
  fd_ = -1;
  pending_.clear();
  stats_.disconnects++;
  // A device that is unplugged and replugged gets a new node a moment later: retry on a timer.
  next_open_ = now + options_.retry;
}

int InputTrigger::ReadEvents(TimePoint now) {
  int presses = 0;
  char buffer[64 * sizeof(input_event)];
  while (fd_ >= 0) {
    ssize_t n = ::read(fd_, buffer, sizeof(buffer));
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno == EAGAIN || errno == EWOULDBLOCK) break;
      Disconnect(std::strerror(errno), now);  // ENODEV when the device is unplugged
      break;
    }
    if (n == 0) {
      Disconnect("end of file", now);
      break;
    }
    pending_.append(buffer, static_cast<size_t>(n));
    size_t used = 0;
    while (pending_.size() - used >= sizeof(input_event)) {
      input_event event;
      std::memcpy(&event, pending_.data() + used, sizeof(event));
      used += sizeof(event);
      if (HandleEvent(event)) presses++;
    }
    pending_.erase(0, used);
  }
  return presses;
}

bool InputTrigger::HandleEvent(const input_event& event) {
  if (event.type == EV_SYN && event.code == SYN_DROPPED) {
    Logger("trigger")->warn("trigger device {}: the kernel dropped events (SYN_DROPPED); a press may be lost",
                            options_.device.string());
    return false;
  }
  if (event.type != EV_KEY || event.code != options_.key_code) return false;
  if (event.value == 2) {
    stats_.repeats++;
    return false;
  }
  if (event.value != 1) return false;  // release
  const int64_t t_us = EventTimeUs(event);
  if (last_press_us_ && t_us >= *last_press_us_ &&
      t_us - *last_press_us_ < std::chrono::duration_cast<std::chrono::microseconds>(options_.debounce).count()) {
    stats_.bounces++;
    Logger("trigger")->debug(
        "press {} us after the last one ignored (debounce {} ms)", t_us - *last_press_us_, options_.debounce.count());
    return false;
  }
  last_press_us_ = t_us;
  stats_.presses++;
  Logger("trigger")->info("{} pressed on {}", KeyCodeName(options_.key_code), options_.device.string());
  return true;
}

}  // namespace px::device
