// Writes real `struct input_event` records, as the kernel's evdev would deliver them, into a FIFO
// that stands in for /dev/input/eventN (no uinput on this machine: no kernel modules).
#pragma once

#include <fcntl.h>
#include <linux/input.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

namespace px::device::testing {

inline input_event Event(uint16_t type, uint16_t code, int32_t value, int64_t t_ms) {
  input_event event{};
  event.input_event_sec = t_ms / 1000;
  event.input_event_usec = (t_ms % 1000) * 1000;
  event.type = type;
  event.code = code;
  event.value = value;
  return event;
}

// A key event followed by its SYN_REPORT, as evdev sends them.
inline std::vector<input_event> Key(uint16_t code, int32_t value, int64_t t_ms) {
  return {Event(EV_KEY, code, value, t_ms), Event(EV_SYN, SYN_REPORT, 0, t_ms)};
}

// The writing end of the FIFO: opens once the trigger has opened the reading end.
class EventWriter {
 public:
  // Waits up to `timeout` for a reader (open with O_NONBLOCK fails with ENXIO until then).
  static int OpenWhenRead(const std::filesystem::path& fifo, std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (true) {
      int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
      if (fd >= 0 || errno != ENXIO || std::chrono::steady_clock::now() > end) return fd;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  explicit EventWriter(int fd) : fd_(fd) {}
  ~EventWriter() { Close(); }
  bool ok() const { return fd_ >= 0; }
  bool Write(const std::vector<input_event>& events) {
    return WriteBytes(reinterpret_cast<const char*>(events.data()), events.size() * sizeof(input_event));
  }
  bool WriteBytes(const char* data, size_t size) { return ::write(fd_, data, size) == static_cast<ssize_t>(size); }
  void Close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_ = -1;
};

inline std::vector<input_event> Concat(std::initializer_list<std::vector<input_event>> parts) {
  std::vector<input_event> all;
  for (const auto& part : parts) all.insert(all.end(), part.begin(), part.end());
  return all;
}

}  // namespace px::device::testing
