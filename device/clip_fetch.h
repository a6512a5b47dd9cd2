// The reply to {"cmd":"fetch","job":...}: where a job's clip is, its size and SHA-256, and with
// "inline":true its bytes in base64 (clips up to kMaxInlineClipBytes).
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>

#include "device/storage/job_journal.h"

namespace px::device {

// NOT_FOUND for an unknown job or an evicted clip, FAILED_PRECONDITION for a job without a clip
// yet (or a failed one, with its error), OUT_OF_RANGE when inline bytes are asked for a clip
// over the limit, DATA_LOSS when the journal names a clip that is not on disk.
StatusOr<nlohmann::json> FetchClipReply(const std::string& id, const std::optional<JobRecord>& record,
                                        bool inline_bytes);

// RFC 4648 base64 with padding.
std::string Base64Encode(const std::string& bytes);

}  // namespace px::device
