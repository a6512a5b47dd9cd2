#include "pipeline/io/durable_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <string>
#include <system_error>

#include "pipeline/core/unique_fd.h"

namespace px {
namespace {

namespace fs = std::filesystem;

constexpr uint64_t kBytesPerMb = 1000 * 1000;
constexpr std::string_view kTempMarker = ".tmp-";

using FdCloser = UniqueFd;

fs::path ParentOrDot(const fs::path& path) {
  fs::path parent = path.parent_path();
  return parent.empty() ? fs::path(".") : parent;
}

Status WriteAll(int fd, std::string_view bytes, const fs::path& path, const fs::path& target) {
  size_t written = 0;
  while (written < bytes.size()) {
    ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      return ErrnoToStatus(errno, "write", target.empty() ? path : target, bytes.size());
    }
    written += static_cast<size_t>(n);
  }
  return OkStatus();
}

}  // namespace

Status DiskFullError(const fs::path& dir, uint64_t free_bytes, uint64_t need_bytes) {
  // Free rounds down and need rounds up, so the message never reads "12 MB free, need 12 MB".
  const uint64_t free_mb = free_bytes / kBytesPerMb;
  const uint64_t need_mb = (need_bytes + kBytesPerMb - 1) / kBytesPerMb;
  return ResourceExhaustedError("disk full: " + std::to_string(free_mb) + " MB free under " + dir.string() + ", need " +
                                std::to_string(need_mb) + " MB");
}

StatusOr<uint64_t> FreeBytes(const fs::path& path) {
  struct statvfs info {};
  if (::statvfs(path.c_str(), &info) != 0) {
    return ErrnoToStatus(errno, "statvfs", path);
  }
  return static_cast<uint64_t>(info.f_bavail) * static_cast<uint64_t>(info.f_frsize);
}

Status CheckFreeSpace(const fs::path& dir, uint64_t need_bytes) {
  PX_ASSIGN_OR_RETURN(uint64_t free_bytes, FreeBytes(dir));
  if (free_bytes < need_bytes) return DiskFullError(dir, free_bytes, need_bytes);
  return OkStatus();
}

Status ErrnoToStatus(int err, std::string_view what, const fs::path& path, uint64_t need_bytes) {
  const std::string context = std::string(what) + " " + path.string() + ": " + std::strerror(err);
  switch (err) {
    case ENOSPC:
    case EDQUOT:
    case EFBIG: {
      const fs::path dir = ParentOrDot(path);
      auto free_bytes = FreeBytes(dir);
      // need_bytes is only what this write wanted; say at least 1 byte so the message is honest.
      return DiskFullError(dir, free_bytes.ok() ? *free_bytes : 0, need_bytes == 0 ? 1 : need_bytes)
          .WithContext(std::string(what) + " " + path.string());
    }
    case ENOENT:
      return NotFoundError(context);
    case EACCES:
    case EPERM:
    case EROFS:
      return FailedPreconditionError(context);
    case EIO:
      return DataLossError(context);
    default:
      return InternalError(context);
  }
}

fs::path TemporaryPathFor(const fs::path& path) {
  static std::atomic<uint64_t> counter{0};
  const std::string name = "." + path.stem().string() + std::string(kTempMarker) + std::to_string(::getpid()) + "-" +
                           std::to_string(counter.fetch_add(1)) + path.extension().string();
  return path.parent_path() / name;
}

bool IsTemporaryName(const std::string& filename) {
  return filename.size() > 1 && filename[0] == '.' && filename.find(kTempMarker) != std::string::npos;
}

namespace {

// Alive: it exists and is not a zombie (a dead worker its parent's death left unreaped).
bool ProcessIsAlive(pid_t pid) {
  if (::kill(pid, 0) != 0) return false;
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return true;  // no /proc: trust kill()
  const size_t name_end = line.rfind(')');     // the name may hold spaces and parentheses
  return name_end == std::string::npos || name_end + 2 >= line.size() || line[name_end + 2] != 'Z';
}

}  // namespace

int RemoveStaleTemporaries(const fs::path& dir) {
  std::error_code ec;
  int removed = 0;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (!IsTemporaryName(name)) continue;
    // Leave temporaries of live processes alone (a CLI run writing beside the daemon).
    const size_t pid_at = name.find(kTempMarker) + kTempMarker.size();
    const pid_t pid = static_cast<pid_t>(std::strtol(name.c_str() + pid_at, nullptr, 10));
    if (pid > 0 && pid != ::getpid() && ProcessIsAlive(pid)) continue;
    std::error_code remove_ec;
    if (fs::remove_all(it->path(), remove_ec) > 0) ++removed;
  }
  return removed;
}

Status FsyncDir(const fs::path& dir) {
  int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return ErrnoToStatus(errno, "open folder", dir);
  FdCloser closer(fd);
  if (::fsync(fd) != 0) return ErrnoToStatus(errno, "fsync folder", dir);
  return OkStatus();
}

Status FsyncFile(const fs::path& path) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return ErrnoToStatus(errno, "open", path);
  FdCloser closer(fd);
  if (::fsync(fd) != 0) return ErrnoToStatus(errno, "fsync", path);
  return OkStatus();
}

Status RenameDurably(const fs::path& from, const fs::path& to) {
  if (::rename(from.c_str(), to.c_str()) != 0) {
    return ErrnoToStatus(errno, "rename " + from.string() + " to", to);
  }
  return FsyncDir(ParentOrDot(to));
}

Status WriteFileAtomically(const fs::path& path, std::string_view bytes, const std::function<Status()>& before_rename) {
  const fs::path temp = TemporaryPathFor(path);
  int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return ErrnoToStatus(errno, "create", temp, bytes.size());
  FdCloser closer(fd);
  Status status = WriteAll(fd, bytes, temp, path);
  if (status.ok() && ::fsync(fd) != 0) status = ErrnoToStatus(errno, "fsync", temp, bytes.size());
  if (status.ok()) {
    if (int err = closer.Close(); err != 0) status = ErrnoToStatus(err, "close", temp, bytes.size());
  }
  if (status.ok() && before_rename) status = before_rename();
  if (status.ok()) status = RenameDurably(temp, path);
  if (!status.ok()) ::unlink(temp.c_str());
  return status;
}

StatusOr<std::string> ReadFileToString(const fs::path& path) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return ErrnoToStatus(errno, "open", path);
  FdCloser closer(fd);
  std::string contents;
  char buffer[65536];
  while (true) {
    ssize_t n = ::read(fd, buffer, sizeof(buffer));
    if (n < 0) {
      if (errno == EINTR) continue;
      return ErrnoToStatus(errno, "read", path);
    }
    if (n == 0) break;
    contents.append(buffer, static_cast<size_t>(n));
  }
  return contents;
}

StatusOr<std::vector<uint8_t>> ReadFileBytes(const fs::path& path, uint64_t max_bytes) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return ErrnoToStatus(errno, "open", path);
  FdCloser closer(fd);
  struct stat info {};
  if (::fstat(fd, &info) != 0) return ErrnoToStatus(errno, "fstat", path);
  if (!S_ISREG(info.st_mode)) return InvalidArgumentError(path.string() + ": not a regular file");
  const uint64_t size = static_cast<uint64_t>(info.st_size);
  if (size > max_bytes) {
    return InvalidArgumentError(path.string() + ": " + std::to_string(size) + " bytes, more than the " +
                                std::to_string(max_bytes) + " allowed");
  }
  std::vector<uint8_t> bytes(size);
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return ErrnoToStatus(errno, "read", path);
    }
    if (n == 0) break;  // shrank while reading
    done += static_cast<size_t>(n);
  }
  bytes.resize(done);
  return bytes;
}

}  // namespace px
