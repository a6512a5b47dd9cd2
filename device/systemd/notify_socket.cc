#include "device/systemd/notify_socket.h"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstring>

namespace px::device {
namespace {

// Fills `address` and returns its length for connect/sendto, or 0 when the name does not fit.
socklen_t FillAddress(std::string_view name, sockaddr_un* address) {
  std::memset(address, 0, sizeof(*address));
  address->sun_family = AF_UNIX;
  if (name.size() > sizeof(address->sun_path) - (name[0] == '@' ? 0 : 1)) return 0;
  std::memcpy(address->sun_path, name.data(), name.size());
  if (name[0] == '@') {
    // Abstract: a leading NUL, and the length counts exactly the name's bytes (no terminator).
    address->sun_path[0] = '\0';
    return static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + name.size());
  }
  return static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + name.size() + 1);
}

}  // namespace

StatusOr<std::unique_ptr<NotifySocket>> NotifySocket::Open(std::string_view address) {
  const std::string what = "NOTIFY_SOCKET '" + std::string(address) + "'";
  if (address.empty()) return InvalidArgumentError(what + ": empty");
  if (address[0] != '/' && address[0] != '@') {
    return InvalidArgumentError(what +
                                ": not an absolute path or an abstract '@' name (other families are not supported)");
  }
  if (address.size() < 2) return InvalidArgumentError(what + ": no name");
  sockaddr_un probe;
  if (FillAddress(address, &probe) == 0) {
    return InvalidArgumentError(what + ": longer than " + std::to_string(sizeof(probe.sun_path) - 1) + " bytes");
  }
  int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return UnavailableError(what + ": socket: " + std::strerror(errno));
  return std::unique_ptr<NotifySocket>(new NotifySocket(fd, std::string(address)));
}

NotifySocket::~NotifySocket() {
  if (fd_ >= 0) ::close(fd_);
}

Status NotifySocket::Send(std::string_view message) {
  sockaddr_un address;
  const socklen_t length = FillAddress(address_, &address);
  ssize_t n;
  do {
    n = ::sendto(fd_,
                 message.data(),
                 message.size(),
                 MSG_NOSIGNAL | MSG_DONTWAIT,
                 reinterpret_cast<const sockaddr*>(&address),
                 length);
  } while (n < 0 && errno == EINTR);
  if (n < 0) return UnavailableError("NOTIFY_SOCKET '" + address_ + "': send: " + std::strerror(errno));
  if (static_cast<size_t>(n) != message.size()) {
    return UnavailableError("NOTIFY_SOCKET '" + address_ + "': short send");
  }
  return OkStatus();
}

}  // namespace px::device
