// Thin, testable wrappers over the V4L2 system calls: an owning file descriptor, ioctl with EINTR
// retry, and the translation of errno into a px::Status that names the device and the call.
#pragma once

#include <cerrno>
#include <string>
#include <utility>

#include "pipeline/core/status.h"

namespace px::v4l2 {

// Owns one open file descriptor; closes it on destruction.
class UniqueFd {
 public:
  UniqueFd() = default;
  explicit UniqueFd(int fd) : fd_(fd) {}
  ~UniqueFd() { Reset(); }
  UniqueFd(UniqueFd&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  UniqueFd& operator=(UniqueFd&& other) noexcept {
    if (this != &other) {
      Reset();
      fd_ = std::exchange(other.fd_, -1);
    }
    return *this;
  }
  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;

  int get() const { return fd_; }
  bool valid() const { return fd_ >= 0; }
  void Reset();

 private:
  int fd_ = -1;
};

// ioctl(2), retried while interrupted by a signal. Returns 0 or -1 with errno set.
int Ioctl(int fd, unsigned long request, void* arg);

// Opens a V4L2 node for non-blocking capture (blocking comes from our own deadline loop, since
// poll(2) may report a node ready when it is not, as under umockdev). Errors are those of
// ErrnoStatus with call "open".
StatusOr<UniqueFd> OpenDevice(const std::string& device);

// errno after a failed call on `device`, as a Status whose code says what the caller can do:
//   ENODEV, ENXIO, EIO, ESHUTDOWN -> UNAVAILABLE "camera vanished"
//   EBUSY                          -> FAILED_PRECONDITION "in use by another program"
//   ENOENT                         -> NOT_FOUND
//   EACCES, EPERM                  -> FAILED_PRECONDITION "permission denied"
//   anything else                  -> INTERNAL
// The message reads "v4l2:/dev/video0: <what>: <call>: <strerror>".
Status ErrnoStatus(const std::string& device, const std::string& call, int err);

// True for the errno values that mean the device is gone.
bool IsVanishedErrno(int err);

}  // namespace px::v4l2
