// The reply to {"cmd":"fetch","job":...}: where a job's clip is, its size and SHA-256, and with
// "inline":true its bytes in base64 (clips up to kMaxInlineClipBytes).
// A fetch never leaves the clip store: the id must be a job id (digits), the clip must be
// clips/<id>.mp4 under the storage root (whatever path the journal record names), and it is
// opened without following symbolic links (neither clips/ nor the file may be one) and must be a
// regular file. What is hashed and sent is read from that one open file.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>

#include "device/storage/job_journal.h"
#include "device/storage/storage_layout.h"

namespace px::device {

// NOT_FOUND for an unknown job or an evicted clip, FAILED_PRECONDITION for a job without a clip
// yet (or a failed one, with its error), OUT_OF_RANGE when inline bytes are asked for a clip
// over the limit, DATA_LOSS when the journal names a clip that is not on disk, INVALID_ARGUMENT
// for an id that is not one, PERMISSION_DENIED for a symbolic link (clips/ or the clip) or
// anything but a regular file.
StatusOr<nlohmann::json> FetchClipReply(const std::string& id,
                                        const std::optional<JobRecord>& record,
                                        bool inline_bytes,
                                        const StorageLayout& layout);

// RFC 4648 base64 with padding.
std::string Base64Encode(const std::string& bytes);

}  // namespace px::device
