#include "device/storage/storage_layout.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>

#include "pipeline/core/log.h"
#include "pipeline/io/durable_file.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;

// Creates `dir` and any missing parents, fsyncing each new entry into its parent.
Status CreateDirDurably(const fs::path& dir) {
  std::error_code ec;
  if (fs::is_directory(dir, ec)) return OkStatus();
  if (fs::exists(dir, ec)) return FailedPreconditionError(dir.string() + ": exists and is not a folder");
  if (dir.has_parent_path() && dir.parent_path() != dir) PX_RETURN_IF_ERROR(CreateDirDurably(dir.parent_path()));
  if (!fs::create_directory(dir, ec) && ec) {
    return ErrnoToStatus(ec.value(), "create folder", dir);
  }
  return FsyncDir(dir.parent_path());
}

// `dir` to 0750 (02750 and owned by `group` when given).
Status RestrictFolder(const fs::path& dir, std::optional<gid_t> group) {
  if (group && ::chown(dir.c_str(), static_cast<uid_t>(-1), *group) != 0) {
    const int err = errno;
    return PermissionDeniedError(dir.string() + ": cannot give it to group " + std::to_string(*group) +
                                 " (storage.group): " + std::strerror(err) +
                                 (err == EPERM ? "; the daemon's user must be a member of that group" : ""));
  }
  if (::chmod(dir.c_str(), group ? 02750 : 0750) != 0) return ErrnoToStatus(errno, "chmod", dir);
  return OkStatus();
}

}  // namespace

Status StorageOptions::Validate() const {
  if (root.empty()) return InvalidArgumentError("storage.root: empty");
  return OkStatus();
}

StorageLayout::StorageLayout(const fs::path& root) {
  std::error_code ec;
  fs::path absolute = fs::absolute(root, ec);
  root_ = (ec ? root : absolute).lexically_normal();
  // "a/b/" normalises to "a/b/"; drop the trailing separator so paths join cleanly.
  if (!root_.has_filename() && root_.has_parent_path() && root_ != root_.root_path()) root_ = root_.parent_path();
}

Status StorageLayout::Prepare(std::optional<gid_t> group) const {
  const mode_t previous = ::umask(0);
  ::umask(previous | 027);
  for (const fs::path& dir : {root_, CapturesDir(), ClipsDir(), JobsDir()}) {
    PX_RETURN_IF_ERROR(CreateDirDurably(dir));
    PX_RETURN_IF_ERROR(RestrictFolder(dir, group));
  }
  int removed = 0;
  for (const fs::path& dir : {CapturesDir(), ClipsDir(), JobsDir()}) removed += RemoveStaleTemporaries(dir);
  // A capture interrupted while its recording was written leaves temporaries inside captures/<id>/.
  std::error_code ec;
  for (fs::directory_iterator it(CapturesDir(), ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_directory(ec)) removed += RemoveStaleTemporaries(it->path());
  }
  if (removed > 0) {
    Logger("device")->warn(
        "removed {} unfinished temporary file(s) under {} left by an interrupted write", removed, root_.string());
  }
  return OkStatus();
}

fs::path StorageLayout::FindClip(const std::string& job_id) const {
  std::error_code ec;
  for (const char* extension : {".mp4", ".gif", ".webp", ""}) {
    const fs::path candidate = ClipsDir() / (job_id + extension);
    if (fs::exists(candidate, ec)) return candidate;
  }
  return ClipPath(job_id);
}

fs::path ClipReportPathFor(const fs::path& clip_path) {
  fs::path report = clip_path;
  report.replace_extension(".json");
  return report;
}

fs::path ClipPosterPathFor(const fs::path& clip_path) {
  fs::path poster = clip_path;
  poster.replace_extension(".poster.jpg");
  return poster;
}

fs::path ClipPreviewPathFor(const fs::path& clip_path) {
  fs::path preview = clip_path;
  preview.replace_extension(".preview.webp");
  return preview;
}

fs::path ClipShotPathFor(const fs::path& clip_path) {
  fs::path shot = clip_path;
  shot.replace_extension(".shot.json");
  return shot;
}

}  // namespace px::device
