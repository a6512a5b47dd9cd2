// Storage limits: how much the daemon's files take, and room for the next capture made by
// evicting the oldest finished clips. A job is evicted whole (clip, its report and its raw
// capture: a done job's capture has served its purpose, and keeping captures without clips would
// fill the disk with data the user never sees); its journal record stays, marked in `note`.
// Never evicted: any job that is not done (capturing, saved, processing: the capture is the only
// copy of a shot that has no clip yet; failed: the user may still want to retry it) and the
// newest done job (the clip just made, likely not fetched yet).
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "device/storage/job_journal.h"
#include "device/storage/storage_layout.h"
#include "pipeline/core/status.h"

namespace px::device {

struct StorageUsage {
  uint64_t used_bytes = 0;       // files under the root
  uint64_t free_bytes = 0;       // free on its file system (statvfs f_bavail)
  uint64_t evictable_bytes = 0;  // what evicting every evictable job would free
  uint64_t next_job_bytes = 0;   // estimate: the newest capture with its clip (0 before the first)
  bool full = false;             // a capture would be refused even after evicting everything evictable
  std::string reason;            // why, when full: the same message the press fails with
  Status shortfall;              // that refusal as a status (RESOURCE_EXHAUSTED), OK when a capture fits
};

// Walks the root. Errors name the folder.
StatusOr<StorageUsage> MeasureStorage(const StorageLayout& layout,
                                      const StorageOptions& options,
                                      const JobJournal& journal);

// {"used_mb":..,"free_mb":..,"quota_mb":..,"min_free_mb":..,"evictable_mb":..,"full":false,"reason":""}
nlohmann::json StorageUsageToJson(const StorageUsage& usage, const StorageOptions& options);

// Removes a job's clip (any format), its report, poster, preview and shot, and its raw capture, then
// fsyncs both folders. `why` names the operation in errors ("evict", "delete").
Status RemoveJobFiles(const StorageLayout& layout, const std::string& id, std::string_view why);

// Before a capture: evicts the oldest evictable jobs until the files under root plus one more
// job (the newest capture and its clip, as an estimate) fit storage.quota_mb, and
// storage.min_free_mb is free.
// Returns the ids evicted. RESOURCE_EXHAUSTED when that is impossible: the disk-full message
// ("disk full: 12 MB free under /r, need 200 MB") or "storage quota: 480 MB used of 500 MB under
// /r, the next job needs about 30 MB; nothing left to evict (...)".
StatusOr<std::vector<std::string>> MakeRoomForCapture(const StorageLayout& layout,
                                                      const StorageOptions& options,
                                                      JobJournal* journal);

}  // namespace px::device
