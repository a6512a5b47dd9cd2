// A parallaxd child process, for the crash tests and the soak tool: started with posix_spawn
// (its stdout and stderr to a log file, chosen environment variables set or removed), signalled,
// waited for with a bound (never a hang), its resident memory read from /proc, and killed and
// reaped on destruction if it is still running.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "device/control/control_client.h"
#include "pipeline/core/status.h"

namespace px::device {

struct DaemonProcessOptions {
  std::filesystem::path binary;   // the parallaxd executable
  std::vector<std::string> args;  // after argv[0]
  // Set in the child (value) or removed from it (nullopt); everything else is inherited.
  std::vector<std::pair<std::string, std::optional<std::string>>> env;
  std::filesystem::path log_path;  // stdout and stderr, appended
};

class DaemonProcess {
 public:
  // INVALID_ARGUMENT for a missing binary; INTERNAL naming the errno when the spawn fails.
  static StatusOr<std::unique_ptr<DaemonProcess>> Start(const DaemonProcessOptions& options);
  ~DaemonProcess();  // SIGKILL and reap when still running
  DaemonProcess(const DaemonProcess&) = delete;
  DaemonProcess& operator=(const DaemonProcess&) = delete;

  pid_t pid() const { return pid_; }
  bool running();  // false once it has exited (and was reaped)
  void Signal(int signal);
  // The exit code, or 128 + signal; DEADLINE_EXCEEDED after `timeout` (the process is then
  // killed with SIGKILL and reaped, so nothing is left behind).
  StatusOr<int> WaitExit(std::chrono::milliseconds timeout);
  // SIGKILL, then reap: what a power cut does to the process.
  Status KillHard();
  // VmRSS from /proc/<pid>/status.
  StatusOr<uint64_t> RssBytes() const;
  // The log so far.
  std::string Log() const;
  // Polls the log until it contains `text`; DEADLINE_EXCEEDED (with the log's tail) after
  // `timeout`, UNAVAILABLE when the process exits first.
  Status WaitForLog(const std::string& text, std::chrono::milliseconds timeout);
  // Connects to the control socket once the daemon listens there (polling); UNAVAILABLE when
  // the process exits first, DEADLINE_EXCEEDED after `timeout`.
  StatusOr<std::unique_ptr<ControlClient>> Connect(const std::filesystem::path& socket,
                                                   std::chrono::milliseconds timeout);

 private:
  DaemonProcess(pid_t pid, std::filesystem::path log) : pid_(pid), log_path_(std::move(log)) {}
  std::string LogTail() const;
  pid_t pid_;
  std::optional<int> exit_code_;
  std::filesystem::path log_path_;
};

}  // namespace px::device
