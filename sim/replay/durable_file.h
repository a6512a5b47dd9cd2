// Small POSIX file helpers for recordings: durable writes (temporary name, fsync, rename),
// directory syncs, whole-file reads, and errno -> Status with the path in the message.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string_view>
#include <vector>

#include "pipeline/core/status.h"

namespace px::replay {

// Maps an errno from `action` ("writing", "renaming", ...) on `path` to a Status naming both.
// ENOSPC, EDQUOT and EFBIG give RESOURCE_EXHAUSTED and add the free space left on that file
// system; ENOENT NOT_FOUND; EACCES, EPERM, EROFS FAILED_PRECONDITION; EIO DATA_LOSS.
Status FileError(int error_number, const std::filesystem::path& path, std::string_view action);

// The temporary sibling a durable write goes through: "<dir>/.<name>.tmp".
std::filesystem::path TemporaryPathFor(const std::filesystem::path& path);

// Writes `bytes` to TemporaryPathFor(path), fsyncs it, calls `before_rename` (if set; a non-OK
// result aborts like an I/O error), then renames it to `path`. On any failure the temporary
// file is removed and `path` is untouched. The caller syncs the folder (SyncDirectory).
Status WriteFileDurably(const std::filesystem::path& path, std::span<const uint8_t> bytes,
                        const std::function<Status()>& before_rename = {});

// fsync on the folder itself, so the renames inside it survive a power cut.
Status SyncDirectory(const std::filesystem::path& dir);

// Reads a regular file whole. NOT_FOUND when absent; INVALID_ARGUMENT when it is not a regular
// file or larger than `max_bytes`.
StatusOr<std::vector<uint8_t>> ReadWholeFile(const std::filesystem::path& path, uint64_t max_bytes);

}  // namespace px::replay
