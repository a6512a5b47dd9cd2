#include "device/clip_fetch.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <nlohmann/json.hpp>
#include <span>
#include <system_error>

#include "capture/sha256.h"
#include "device/control/control_protocol.h"
#include "pipeline/core/unique_fd.h"
#include "pipeline/io/durable_file.h"

namespace px::device {

std::string Base64Encode(const std::string& bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = (uint8_t(bytes[i]) << 16) | (uint8_t(bytes[i + 1]) << 8) | uint8_t(bytes[i + 2]);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i + 1 == bytes.size()) {
    const uint32_t v = uint8_t(bytes[i]) << 16;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == bytes.size()) {
    const uint32_t v = (uint8_t(bytes[i]) << 16) | (uint8_t(bytes[i + 1]) << 8);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

namespace {

using FdCloser = UniqueFd;

// clips/<name> (the job's clip file: <id>.mp4, .gif or .webp) opened below the storage root without
// following a symbolic link anywhere after the root (which is the daemon's own configuration), and
// only if it is a regular file.
StatusOr<int> OpenClipInStore(const StorageLayout& layout, const std::string& name, uint64_t* size) {
  const std::filesystem::path clip = layout.ClipsDir() / name;
  FdCloser root(::open(layout.root().c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (root.get() < 0) return ErrnoToStatus(errno, "open", layout.root());
  FdCloser clips(::openat(root.get(), "clips", O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
  if (clips.get() < 0) {
    if (errno == ELOOP || errno == ENOTDIR) {
      return PermissionDeniedError(layout.ClipsDir().string() +
                                   " is not a folder of the store (a symbolic link?); refusing to fetch through it");
    }
    return ErrnoToStatus(errno, "open", layout.ClipsDir());
  }
  // O_NONBLOCK: a FIFO planted under the clip's name must not hang the daemon.
  int fd = ::openat(clips.get(), name.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ELOOP) {
      return PermissionDeniedError("clip " + clip.string() +
                                   " is a symbolic link; refusing to follow it out of the clip store");
    }
    if (errno == ENOENT) return DataLossError("clip " + clip.string() + " is missing");
    return ErrnoToStatus(errno, "open", clip);
  }
  struct stat info {};
  if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
    ::close(fd);
    return PermissionDeniedError("clip " + clip.string() + " is not a regular file; refusing to read it");
  }
  // A clip the daemon wrote has one link and is the daemon's: another link planted under its name
  // could expose any file its user can read.
  if (info.st_nlink != 1 || info.st_uid != ::geteuid()) {
    ::close(fd);
    return PermissionDeniedError("clip " + clip.string() +
                                 (info.st_nlink != 1 ? " has " + std::to_string(info.st_nlink) + " hard links"
                                                     : " is not owned by the daemon's user") +
                                 "; refusing to read it");
  }
  *size = static_cast<uint64_t>(info.st_size);
  return fd;
}

StatusOr<std::string> ReadAll(int fd, uint64_t size, const std::filesystem::path& path) {
  std::string bytes(size, '\0');
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return ErrnoToStatus(errno, "read", path);
    if (n == 0) return DataLossError("clip " + path.string() + " shrank while it was read");
    done += static_cast<size_t>(n);
  }
  return bytes;
}

}  // namespace

StatusOr<nlohmann::json> FetchClipReply(const std::string& id,
                                        const std::optional<JobRecord>& record,
                                        bool inline_bytes,
                                        const StorageLayout& layout) {
  if (!ParseJobId(id)) return InvalidArgumentError("job '" + id + "': not a job id");
  if (!record) return NotFoundError("job '" + id + "': no such job");
  if (record->state == JobState::kFailed) {
    return FailedPreconditionError("job " + id + " failed, it has no clip: " + record->error);
  }
  if (record->state != JobState::kDone) {
    return FailedPreconditionError("job " + id + " is " + std::string(JobStateName(record->state)) +
                                   "; its clip is not made yet");
  }
  if (record->clip_path.empty()) return NotFoundError("job " + id + ": its clip is gone: " + record->note);
  // Always clips/<id>.<format> under this store, whatever path the journal record holds (it may be
  // from before the store moved, or edited): a record cannot point a fetch elsewhere.
  const std::filesystem::path clip = layout.FindClip(id);
  std::error_code ec;
  if (!clip.has_extension() && std::filesystem::is_directory(clip, ec) && !std::filesystem::is_symlink(clip, ec)) {
    return FailedPreconditionError("job " + id +
                                   ": its clip is a folder of PNG frames (clip.format png), not one "
                                   "file; read the frames from " +
                                   clip.string());
  }
  uint64_t size = 0;
  StatusOr<int> opened = OpenClipInStore(layout, clip.filename().string(), &size);
  if (!opened.ok()) return opened.status().WithContext("job " + id);
  FdCloser fd(*opened);
  if (inline_bytes && size > kMaxInlineClipBytes) {
    return OutOfRangeError("job " + id + ": clip of " + std::to_string(size) + " bytes is over the inline limit of " +
                           std::to_string(kMaxInlineClipBytes) + "; read it from " + clip.string());
  }
  StatusOr<std::string> bytes = ReadAll(fd.get(), size, clip);
  if (!bytes.ok()) return bytes.status().WithContext("job " + id);
  nlohmann::json reply = {
      {"ok", true},
      {"job", id},
      {"path", clip.string()},
      {"bytes", bytes->size()},
      {"sha256", capture::Sha256HexOfText(*bytes)},
  };
  if (inline_bytes) reply["data"] = Base64Encode(*bytes);
  return reply;
}

}  // namespace px::device
