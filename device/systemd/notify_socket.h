// The sd_notify(3) wire protocol, spoken directly: one datagram of newline-separated
// "KEY=value" lines to the AF_UNIX socket named by $NOTIFY_SOCKET, where a leading '@' names an
// abstract socket. No libsystemd: this is all of it parallaxd needs.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "pipeline/core/status.h"

namespace px::device {

class NotifySocket {
 public:
  // `address`: a path ("/run/systemd/notify") or an abstract name ("@/org/.../notify").
  // INVALID_ARGUMENT for an empty, relative or too long address, or one of another family
  // ("vsock:..."); UNAVAILABLE when no socket can be made.
  static StatusOr<std::unique_ptr<NotifySocket>> Open(std::string_view address);
  ~NotifySocket();
  NotifySocket(const NotifySocket&) = delete;
  NotifySocket& operator=(const NotifySocket&) = delete;

  // Sends one message ("READY=1\nSTATUS=idle") without blocking. UNAVAILABLE naming the address
  // and errno text when it cannot be delivered (nobody listening, queue full).
  Status Send(std::string_view message);
  const std::string& address() const { return address_; }

 private:
  NotifySocket(int fd, std::string address) : fd_(fd), address_(std::move(address)) {}
  int fd_ = -1;
  std::string address_;
};

}  // namespace px::device
