// Durable file helpers (recordings, clips, the daemon's state): a file is either absent, the old version or the new
// one, never half-written, even across a power cut (write a temporary beside it, fsync, rename, fsync the folder). A
// full disk is RESOURCE_EXHAUSTED with a message saying how much is free and needed.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/status.h"

namespace px {

// Writes `bytes` to `path` atomically: a temporary in the same folder, write, fsync, rename over
// `path`, fsync the folder. On failure the temporary is removed and `path` is untouched.
// `before_rename`, when set, runs once the temporary is complete (tests use it to stop exactly
// where a crash would); a non-OK result aborts the write like an I/O error.
Status WriteFileAtomically(const std::filesystem::path& path,
                           std::string_view bytes,
                           const std::function<Status()>& before_rename = {});

// Reads a whole file. NOT_FOUND when it is absent.
StatusOr<std::string> ReadFileToString(const std::filesystem::path& path);
// Reads a whole regular file of at most `max_bytes`. NOT_FOUND when absent; INVALID_ARGUMENT
// when it is not a regular file or is larger (a guard against reading a device or a huge file).
StatusOr<std::vector<uint8_t>> ReadFileBytes(const std::filesystem::path& path, uint64_t max_bytes);

// fsync of a folder, so that a rename or create inside it survives a power cut.
Status FsyncDir(const std::filesystem::path& dir);
// fsync of an existing file's contents.
Status FsyncFile(const std::filesystem::path& path);

// Renames `from` over `to` (same file system) and fsyncs the destination folder.
Status RenameDurably(const std::filesystem::path& from, const std::filesystem::path& to);

// Bytes available to an unprivileged writer on the file system holding `path` (statvfs f_bavail).
StatusOr<uint64_t> FreeBytes(const std::filesystem::path& path);

// RESOURCE_EXHAUSTED "disk full: 12 MB free under /var/lib/parallax, need 80 MB". `free_bytes`
// is what is free now (measured by the caller), `need_bytes` what the operation needed.
Status DiskFullError(const std::filesystem::path& dir, uint64_t free_bytes, uint64_t need_bytes);

// OK when at least `need_bytes` are free under `dir`, else DiskFullError.
Status CheckFreeSpace(const std::filesystem::path& dir, uint64_t need_bytes);

// Converts an errno from an operation on `path` into a Status: ENOSPC/EDQUOT become the disk-full
// error (measuring free space under the path's folder against `need_bytes`), ENOENT NOT_FOUND,
// EACCES/EPERM/EROFS FAILED_PRECONDITION, EIO DATA_LOSS, others INTERNAL. `what` names the
// operation: "write", "rename".
Status ErrnoToStatus(int err, std::string_view what, const std::filesystem::path& path, uint64_t need_bytes = 0);

// A unique hidden name in the same folder that keeps the extension (libavformat picks the
// container from it): clips/0007.mp4 -> clips/.0007.tmp-<pid>-<n>.mp4.
std::filesystem::path TemporaryPathFor(const std::filesystem::path& path);
// True for names made by TemporaryPathFor.
bool IsTemporaryName(const std::string& filename);
// Removes temporaries left in `dir` (not recursive) by a process that died mid-write.
// Returns how many were removed.
int RemoveStaleTemporaries(const std::filesystem::path& dir);

}  // namespace px
