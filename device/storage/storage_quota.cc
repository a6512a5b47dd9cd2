#include "device/storage/storage_quota.h"

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <system_error>

#include "pipeline/core/log.h"
#include "pipeline/io/durable_file.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;

constexpr double kBytesPerMb = 1000.0 * 1000.0;

uint64_t BytesUnder(const fs::path& path) {
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) return fs::file_size(path, ec);
  uint64_t total = 0;
  for (fs::recursive_directory_iterator it(path, fs::directory_options::skip_permission_denied, ec), end;
       !ec && it != end;
       it.increment(ec)) {
    std::error_code size_ec;
    if (it->is_regular_file(size_ec)) {
      const uint64_t size = it->file_size(size_ec);
      if (!size_ec) total += size;
    }
  }
  return total;
}

// What one done job holds on disk: clip, report, capture.
uint64_t JobBytes(const StorageLayout& layout, const std::string& id) {
  const fs::path clip = layout.FindClip(id);
  return BytesUnder(clip) + BytesUnder(ClipReportPathFor(clip)) + BytesUnder(ClipPosterPathFor(clip)) +
         BytesUnder(ClipPreviewPathFor(clip)) + BytesUnder(layout.CaptureDir(id));
}

bool HasFiles(const StorageLayout& layout, const std::string& id) {
  std::error_code ec;
  return fs::exists(layout.FindClip(id), ec) || fs::exists(layout.CaptureDir(id), ec);
}

// Done jobs that may go, oldest first: not the newest done job, and only while they hold files.
std::vector<std::string> Evictable(const StorageLayout& layout, const JobJournal& journal) {
  std::vector<std::string> done;
  for (const JobRecord& record : journal.List()) {
    if (record.state == JobState::kDone) done.push_back(record.id);
  }
  if (!done.empty()) done.pop_back();  // the clip just made stays
  std::erase_if(done, [&](const std::string& id) { return !HasFiles(layout, id); });
  return done;
}

// The next job's likely size: what the newest finished job holds (capture, clip and report), as
// a fresh capture grows into that; before the first clip, the newest capture alone.
uint64_t NextJobBytes(const StorageLayout& layout, const JobJournal& journal) {
  const std::vector<JobRecord> records = journal.List();
  for (auto it = records.rbegin(); it != records.rend(); ++it) {
    if (it->state == JobState::kDone && HasFiles(layout, it->id)) return JobBytes(layout, it->id);
  }
  std::vector<std::string> ids;
  std::error_code ec;
  for (fs::directory_iterator it(layout.CapturesDir(), ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_directory(ec)) ids.push_back(it->path().filename().string());
  }
  if (ids.empty()) return 0;
  return JobBytes(layout, *std::max_element(ids.begin(), ids.end()));
}

std::string Mb(uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.0f MB", static_cast<double>(bytes) / kBytesPerMb);
  return text;
}

// The refusal for the usage left after evicting `evictable` bytes; OK when a capture fits.
Status Shortfall(const StorageLayout& layout,
                 const StorageOptions& options,
                 const StorageUsage& usage,
                 uint64_t evictable,
                 size_t kept_jobs) {
  if (usage.free_bytes + evictable < options.min_free_bytes) {
    return DiskFullError(layout.root(), usage.free_bytes, options.min_free_bytes);
  }
  if (options.quota_bytes > 0 && usage.used_bytes - evictable + usage.next_job_bytes > options.quota_bytes) {
    return ResourceExhaustedError(
        "storage quota: " + Mb(usage.used_bytes) + " used of " + Mb(options.quota_bytes) + " under " +
        layout.root().string() + ", the next job needs about " + Mb(usage.next_job_bytes) +
        "; nothing left to evict (" + std::to_string(kept_jobs) +
        " job(s) kept: unprocessed or failed captures and the newest clip are never evicted)");
  }
  return OkStatus();
}

Status Evict(const StorageLayout& layout, JobJournal* journal, const std::string& id, const std::string& why) {
  PX_RETURN_IF_ERROR(RemoveJobFiles(layout, id, "evict"));
  std::optional<JobRecord> record = journal->Get(id);
  if (!record) return OkStatus();
  record->clip_path.clear();
  record->capture_dir.clear();
  record->note = "evicted " + NowIso8601Utc() + " " + why + " (clip and raw capture removed)";
  return journal->Put(*record);
}

}  // namespace

Status RemoveJobFiles(const StorageLayout& layout, const std::string& id, std::string_view why) {
  std::error_code ec;
  const fs::path clip = layout.FindClip(id);
  fs::remove_all(clip, ec);
  if (ec) return ErrnoToStatus(ec.value(), why, clip);
  fs::remove(ClipReportPathFor(clip), ec);
  fs::remove(ClipPosterPathFor(clip), ec);
  fs::remove(ClipPreviewPathFor(clip), ec);
  fs::remove(ClipShotPathFor(clip), ec);
  fs::remove_all(layout.CaptureDir(id), ec);
  if (ec) return ErrnoToStatus(ec.value(), why, layout.CaptureDir(id));
  PX_RETURN_IF_ERROR(FsyncDir(layout.ClipsDir()));
  return FsyncDir(layout.CapturesDir());
}

StatusOr<StorageUsage> MeasureStorage(const StorageLayout& layout,
                                      const StorageOptions& options,
                                      const JobJournal& journal) {
  StorageUsage usage;
  PX_ASSIGN_OR_RETURN(usage.free_bytes, FreeBytes(layout.root()));
  usage.used_bytes = BytesUnder(layout.root());
  const std::vector<std::string> evictable = Evictable(layout, journal);
  for (const std::string& id : evictable) usage.evictable_bytes += JobBytes(layout, id);
  usage.evictable_bytes = std::min(usage.evictable_bytes, usage.used_bytes);
  usage.next_job_bytes = NextJobBytes(layout, journal);
  const Status shortfall =
      Shortfall(layout, options, usage, usage.evictable_bytes, journal.List().size() - evictable.size());
  usage.full = !shortfall.ok();
  usage.reason = shortfall.ok() ? "" : shortfall.ToString();
  usage.shortfall = shortfall;
  return usage;
}

nlohmann::json StorageUsageToJson(const StorageUsage& usage, const StorageOptions& options) {
  auto mb = [](uint64_t bytes) { return static_cast<double>(bytes) / kBytesPerMb; };
  return {{"used_mb", mb(usage.used_bytes)},
          {"free_mb", mb(usage.free_bytes)},
          {"quota_mb", mb(options.quota_bytes)},
          {"min_free_mb", mb(options.min_free_bytes)},
          {"evictable_mb", mb(usage.evictable_bytes)},
          {"full", usage.full},
          {"reason", usage.reason}};
}

StatusOr<std::vector<std::string>> MakeRoomForCapture(const StorageLayout& layout,
                                                      const StorageOptions& options,
                                                      JobJournal* journal) {
  std::vector<std::string> evicted;
  const std::vector<std::string> candidates = Evictable(layout, *journal);
  size_t next = 0;
  while (true) {
    StorageUsage usage;
    PX_ASSIGN_OR_RETURN(usage.free_bytes, FreeBytes(layout.root()));
    usage.used_bytes = BytesUnder(layout.root());
    usage.next_job_bytes = NextJobBytes(layout, *journal);
    const Status room = Shortfall(layout, options, usage, 0, journal->List().size() - (candidates.size() - next));
    if (room.ok()) return evicted;
    if (next == candidates.size()) return room;
    const std::string& id = candidates[next++];
    const bool disk = usage.free_bytes < options.min_free_bytes;
    const std::string why = disk ? "to keep storage.min_free_mb free" : "to stay under storage.quota_mb";
    Logger("device")->warn("job {}: evicting its clip and raw capture ({}) {}", id, Mb(JobBytes(layout, id)), why);
    PX_RETURN_IF_ERROR(Evict(layout, journal, id, why));
    evicted.push_back(id);
  }
}

}  // namespace px::device
