// A client for the control socket: one connection, one request line at a time. Used by the
// `parallax` command line and the daemon's tests.
#pragma once

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>

#include "pipeline/core/status.h"

namespace px::device {

class ControlClient {
 public:
  // UNAVAILABLE naming the path when nothing listens there.
  static StatusOr<std::unique_ptr<ControlClient>> Connect(const std::filesystem::path& socket_path);
  ~ControlClient();

  // Sends `request` (one line, no newline) and returns the reply line. DEADLINE_EXCEEDED when
  // no reply arrives within `timeout` (a "wait" may need long); UNAVAILABLE when the daemon
  // closed the connection.
  StatusOr<std::string> Call(const std::string& request,
                             std::chrono::milliseconds timeout = std::chrono::milliseconds(10000));

  // Sends raw bytes without waiting for anything (tests: partial or garbage lines).
  Status SendRaw(const std::string& bytes);
  // Reads one reply line (what Call does after sending).
  StatusOr<std::string> ReadLine(std::chrono::milliseconds timeout);

 private:
  ControlClient(int fd, std::filesystem::path path) : fd_(fd), path_(std::move(path)) {}
  int fd_;
  std::filesystem::path path_;
  std::string buffer_;
};

}  // namespace px::device
