#include "device/systemd/systemd_notifier.h"

#include <unistd.h>

#include <charconv>
#include <cstdlib>
#include <string_view>

#include "device/systemd/watchdog_pinger.h"
#include "pipeline/core/log.h"

namespace px::device {
namespace {

std::optional<int64_t> ParsePositive(std::string_view text) {
  int64_t value = 0;
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size() || value <= 0) return std::nullopt;
  return value;
}

}  // namespace

StatusOr<std::optional<std::chrono::microseconds>> WatchdogIntervalFromEnvironment(const char* watchdog_usec,
                                                                                   const char* watchdog_pid) {
  if (watchdog_usec == nullptr || *watchdog_usec == '\0') return std::optional<std::chrono::microseconds>();
  if (watchdog_pid != nullptr && *watchdog_pid != '\0') {
    std::optional<int64_t> pid = ParsePositive(watchdog_pid);
    if (!pid) return InvalidArgumentError(std::string("WATCHDOG_PID '") + watchdog_pid + "': not a process id");
    if (*pid != ::getpid()) return std::optional<std::chrono::microseconds>();  // meant for another process
  }
  std::optional<int64_t> usec = ParsePositive(watchdog_usec);
  if (!usec) {
    return InvalidArgumentError(std::string("WATCHDOG_USEC '") + watchdog_usec + "': not a positive number");
  }
  return std::optional<std::chrono::microseconds>(std::chrono::microseconds(*usec));
}

StatusOr<std::unique_ptr<SystemdNotifier>> SystemdNotifier::FromEnvironment() {
  const char* address = std::getenv("NOTIFY_SOCKET");
  if (address == nullptr || *address == '\0') return std::unique_ptr<SystemdNotifier>();
  PX_ASSIGN_OR_RETURN(std::unique_ptr<NotifySocket> socket, NotifySocket::Open(address));
  PX_ASSIGN_OR_RETURN(std::optional<std::chrono::microseconds> watchdog,
                      WatchdogIntervalFromEnvironment(std::getenv("WATCHDOG_USEC"), std::getenv("WATCHDOG_PID")));
  Logger("device")->info("systemd: notifying {}{}",
                         address,
                         watchdog ? ", watchdog every " + std::to_string(watchdog->count() / 2000) + " ms" : "");
  return std::make_unique<SystemdNotifier>(std::move(socket), watchdog);
}

SystemdNotifier::SystemdNotifier(std::unique_ptr<NotifySocket> socket,
                                 std::optional<std::chrono::microseconds> watchdog)
    : socket_(std::move(socket)), watchdog_(watchdog) {}

std::shared_ptr<LoopInput> SystemdNotifier::MakeWatchdogPinger() {
  if (!watchdog_) return nullptr;
  return std::make_shared<WatchdogPinger>(*watchdog_, [this] { return socket_->Send("WATCHDOG=1"); });
}

void SystemdNotifier::Send(const std::string& message) {
  Status sent = socket_->Send(message);
  if (!sent.ok()) Logger("device")->warn("systemd notify '{}' failed: {}", message, sent.ToString());
}

void SystemdNotifier::Ready() {
  std::lock_guard<std::mutex> lock(mutex_);
  Send("READY=1\nSTATUS=" + (state_.empty() ? std::string("idle") : state_));
}

void SystemdNotifier::ReportState(const std::string& state, bool stopping) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopping && !stopping_sent_) {
    stopping_sent_ = true;
    state_ = "stopping (" + state + ")";
    Send("STOPPING=1\nSTATUS=" + state_);
    return;
  }
  const std::string status = stopping ? "stopping (" + state + ")" : state;
  if (status == state_) return;
  state_ = status;
  Send("STATUS=" + status);
}

void SystemdNotifier::Stopping() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopping_sent_) return;
  stopping_sent_ = true;
  Send("STOPPING=1\nSTATUS=stopping");
}

}  // namespace px::device
