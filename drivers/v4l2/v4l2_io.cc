#include "drivers/v4l2/v4l2_io.h"

#include <fcntl.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cstring>

namespace px::v4l2 {

void UniqueFd::Reset() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

int Ioctl(int fd, unsigned long request, void* arg) {
  int result;
  do {
    result = ::ioctl(fd, request, arg);
  } while (result == -1 && errno == EINTR);
  return result;
}

StatusOr<UniqueFd> OpenDevice(const std::string& device) {
  int fd;
  do {
    fd = ::open(device.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  } while (fd < 0 && errno == EINTR);
  if (fd < 0) return ErrnoStatus(device, "open", errno);
  return UniqueFd(fd);
}

bool IsVanishedErrno(int err) { return err == ENODEV || err == ENXIO || err == EIO || err == ESHUTDOWN; }

Status ErrnoStatus(const std::string& device, const std::string& call, int err) {
  const std::string prefix = "v4l2:" + device + ": ";
  const std::string detail = call + ": " + std::strerror(err);
  if (IsVanishedErrno(err)) return UnavailableError(prefix + "camera vanished (" + detail + ")");
  if (err == EBUSY) {
    return FailedPreconditionError(prefix + "in use by another program; close it and retry (" + detail + ")");
  }
  if (err == ENOENT) return NotFoundError(prefix + "no such device (" + detail + ")");
  if (err == EACCES || err == EPERM) {
    return FailedPreconditionError(prefix + "permission denied; is the user in the 'video' group? (" + detail + ")");
  }
  return InternalError(prefix + detail);
}

}  // namespace px::v4l2
