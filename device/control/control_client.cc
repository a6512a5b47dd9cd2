#include "device/control/control_client.h"

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace px::device {

namespace fs = std::filesystem;

StatusOr<std::unique_ptr<ControlClient>> ControlClient::Connect(const fs::path& socket_path) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  const std::string text = socket_path.string();
  if (text.size() >= sizeof(address.sun_path)) {
    return InvalidArgumentError("control socket " + text + ": path is too long");
  }
  std::memcpy(address.sun_path, text.c_str(), text.size() + 1);
  int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return InternalError(std::string("socket: ") + std::strerror(errno));
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
    int err = errno;
    ::close(fd);
    return UnavailableError("control socket " + text + ": cannot connect (" + std::strerror(err) +
                            "); is parallaxd running?");
  }
  return std::unique_ptr<ControlClient>(new ControlClient(fd, socket_path));
}

ControlClient::~ControlClient() { ::close(fd_); }

Status ControlClient::SendRaw(const std::string& bytes) {
  size_t sent = 0;
  while (sent < bytes.size()) {
    ssize_t n = ::send(fd_, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      return UnavailableError("control socket " + path_.string() + ": send: " + std::strerror(errno));
    }
    sent += static_cast<size_t>(n);
  }
  return OkStatus();
}

StatusOr<std::string> ControlClient::ReadLine(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (true) {
    if (size_t newline = buffer_.find('\n'); newline != std::string::npos) {
      std::string line = buffer_.substr(0, newline);
      buffer_.erase(0, newline + 1);
      return line;
    }
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      return DeadlineExceededError("control socket " + path_.string() + ": no reply within " +
                                   std::to_string(timeout.count()) + " ms");
    }
    pollfd p{fd_, POLLIN, 0};
    int ready = ::poll(&p, 1, static_cast<int>(left.count()));
    if (ready < 0) {
      if (errno == EINTR) continue;
      return InternalError(std::string("poll: ") + std::strerror(errno));
    }
    if (ready == 0) continue;
    char chunk[4096];
    ssize_t n = ::recv(fd_, chunk, sizeof(chunk), 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      return UnavailableError("control socket " + path_.string() + ": recv: " + std::strerror(errno));
    }
    if (n == 0) return UnavailableError("control socket " + path_.string() + ": the daemon closed the connection");
    buffer_.append(chunk, static_cast<size_t>(n));
  }
}

StatusOr<std::string> ControlClient::Call(const std::string& request, std::chrono::milliseconds timeout) {
  PX_RETURN_IF_ERROR(SendRaw(request + "\n"));
  return ReadLine(timeout);
}

}  // namespace px::device
