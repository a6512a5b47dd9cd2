#include "device/http/access_token.h"

#include <fcntl.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "device/worker/write_all.h"
#include "pipeline/io/durable_file.h"

namespace px::device {

namespace {

constexpr size_t kTokenBytes = 32;

bool IsHexToken(std::string_view text) {
  if (text.size() != 2 * kTokenBytes) return false;
  for (char c : text) {
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

StatusOr<std::string> RandomHex(size_t bytes) {
  std::string raw(bytes, '\0');
  size_t filled = 0;
  while (filled < bytes) {
    const ssize_t got = getrandom(raw.data() + filled, bytes - filled, 0);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) return InternalError(std::string("getrandom: ") + std::strerror(errno));
    filled += static_cast<size_t>(got);
  }
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string hex;
  for (unsigned char c : raw) {
    hex += kDigits[c >> 4];
    hex += kDigits[c & 15];
  }
  return hex;
}

// Writes `text` to `path` atomically with mode 0600 from its creation (never readable by the
// store's group, not even for a moment): a temporary made with O_EXCL, fsynced, renamed into place.
Status WritePrivateFile(const std::filesystem::path& path, const std::string& text) {
  const std::filesystem::path temp = path.parent_path() / ("." + path.filename().string() + ".tmp");
  ::unlink(temp.c_str());
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) return ErrnoToStatus(errno, "create", temp);
  if (const int err = WriteAll(fd, text); err != 0) {
    ::close(fd);
    ::unlink(temp.c_str());
    return ErrnoToStatus(err, "write", temp);
  }
  const bool synced = ::fsync(fd) == 0;
  const int err = errno;
  ::close(fd);
  if (!synced) {
    ::unlink(temp.c_str());
    return ErrnoToStatus(err, "fsync", temp);
  }
  return RenameDurably(temp, path);
}

}  // namespace

StatusOr<std::string> LoadOrCreateAccessToken(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::exists(path, ec)) {
    PX_ASSIGN_OR_RETURN(std::string text, ReadFileToString(path));
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
    if (!IsHexToken(text)) {
      return InvalidArgumentError("access token " + path.string() +
                                  ": not 64 lowercase hex digits; delete it to make a new one");
    }
    if (chmod(path.c_str(), 0600) != 0) return ErrnoToStatus(errno, "chmod", path);
    return text;
  }
  PX_ASSIGN_OR_RETURN(std::string token, RandomHex(kTokenBytes));
  PX_RETURN_IF_ERROR(WritePrivateFile(path, token + "\n"));
  return token;
}

bool TokensEqual(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  unsigned char difference = 0;
  for (size_t i = 0; i < a.size(); ++i) difference |= static_cast<unsigned char>(a[i] ^ b[i]);
  return difference == 0;
}

}  // namespace px::device
