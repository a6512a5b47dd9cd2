#include "sim/replay/durable_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <system_error>
#include <utility>

namespace px::replay {
namespace {

std::string MiB(uintmax_t bytes) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
  return text;
}

// Closes a descriptor on scope exit unless released.
class FdCloser {
 public:
  explicit FdCloser(int fd) : fd_(fd) {}
  ~FdCloser() {
    if (fd_ >= 0) ::close(fd_);
  }
  FdCloser(const FdCloser&) = delete;
  FdCloser& operator=(const FdCloser&) = delete;
  int Release() { return std::exchange(fd_, -1); }

 private:
  int fd_;
};

}  // namespace

Status FileError(int error_number, const std::filesystem::path& path, std::string_view action) {
  std::string message = path.string() + ": " + std::string(action) + " failed: " + std::strerror(error_number) +
                        " (errno " + std::to_string(error_number) + ")";
  switch (error_number) {
    case ENOSPC:
    case EDQUOT:
    case EFBIG: {
      std::error_code ec;
      const std::filesystem::path where = path.has_parent_path() ? path.parent_path() : path;
      const std::filesystem::space_info space = std::filesystem::space(where, ec);
      message += ec ? "; free space unknown (" + ec.message() + ")"
                    : "; " + MiB(space.available) + " free on the file system of " + where.string();
      return ResourceExhaustedError(message);
    }
    case ENOENT:
    case ENOTDIR: return NotFoundError(message);
    case EACCES:
    case EPERM:
    case EROFS: return FailedPreconditionError(message);
    case EEXIST: return Status(StatusCode::kAlreadyExists, message);
    case EIO: return DataLossError(message);
    default: return InternalError(message);
  }
}

std::filesystem::path TemporaryPathFor(const std::filesystem::path& path) {
  return path.parent_path() / ("." + path.filename().string() + ".tmp");
}

Status WriteFileDurably(const std::filesystem::path& path, std::span<const uint8_t> bytes,
                        const std::function<Status()>& before_rename) {
  const std::filesystem::path temporary = TemporaryPathFor(path);
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return FileError(errno, temporary, "creating");
  FdCloser closer(fd);
  auto fail = [&](Status status) {
    ::close(closer.Release());
    ::unlink(temporary.c_str());
    return status;
  };

  size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      return fail(FileError(errno, temporary, "writing"));
    }
    written += static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0) return fail(FileError(errno, temporary, "syncing"));
  // close() can report a deferred write error (NFS, quotas): check it.
  if (::close(closer.Release()) != 0) {
    const int error_number = errno;
    ::unlink(temporary.c_str());
    return FileError(error_number, temporary, "closing");
  }
  if (before_rename) {
    if (Status hooked = before_rename(); !hooked.ok()) {
      ::unlink(temporary.c_str());
      return hooked;
    }
  }
  if (::rename(temporary.c_str(), path.c_str()) != 0) {
    const int error_number = errno;
    ::unlink(temporary.c_str());
    return FileError(error_number, path, "renaming " + temporary.filename().string() + " to");
  }
  return OkStatus();
}

Status SyncDirectory(const std::filesystem::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return FileError(errno, dir, "opening folder to sync");
  FdCloser closer(fd);
  if (::fsync(fd) != 0) return FileError(errno, dir, "syncing folder");
  return OkStatus();
}

StatusOr<std::vector<uint8_t>> ReadWholeFile(const std::filesystem::path& path, uint64_t max_bytes) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ENOENT) return NotFoundError(path.string() + ": missing");
    return FileError(errno, path, "opening");
  }
  FdCloser closer(fd);
  struct stat info {};
  if (::fstat(fd, &info) != 0) return FileError(errno, path, "reading the size of");
  if (!S_ISREG(info.st_mode)) return InvalidArgumentError(path.string() + ": not a regular file");
  const uint64_t size = static_cast<uint64_t>(info.st_size);
  if (size > max_bytes) {
    return InvalidArgumentError(path.string() + ": " + std::to_string(size) + " bytes, more than the " +
                                std::to_string(max_bytes) + " a recording file may have");
  }
  std::vector<uint8_t> bytes(size);
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return FileError(errno, path, "reading");
    }
    if (n == 0) break;  // shrank while we read it
    done += static_cast<size_t>(n);
  }
  bytes.resize(done);
  return bytes;
}

}  // namespace px::replay
