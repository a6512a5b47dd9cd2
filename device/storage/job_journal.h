// The job journal: one JSON record per job in <root>/jobs/<id>.json, rewritten atomically on
// every state change, so after a crash the daemon knows which captures still need a clip.
// A job moves capturing -> saved -> processing -> done, or to failed from any of them.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/status.h"

namespace px::device {

enum class JobState {
  kCapturing,   // pressed; the capture is being taken and written
  kSaved,       // the raw capture is on disk (captures/<id>/); waiting for processing
  kProcessing,  // the clip is being made
  kDone,        // clips/<id>.mp4 exists
  kFailed,      // see `error`
};

std::string_view JobStateName(JobState state);  // "capturing", "saved", "processing", "done", "failed"
StatusOr<JobState> ParseJobState(std::string_view name);
bool IsFinal(JobState state);  // done or failed

// The sequence number a job id stands for: 1 to 18 decimal digits ("000042" -> 42), nullopt for
// anything else. Every id that reaches a path (captures/<id>, clips/<id>.mp4) passes this first.
std::optional<uint64_t> ParseJobId(std::string_view id);

struct JobRecord {
  std::string id;  // "000042": a zero-padded sequence, so name order is press order
  JobState state = JobState::kCapturing;
  std::string created_at;   // ISO 8601 UTC, when the button was pressed
  std::string updated_at;   // ISO 8601 UTC, last state change
  std::string capture_dir;  // absolute, once saved
  std::string clip_path;    // absolute, once done
  double capture_ms = 0;    // taking the frame set
  double save_ms = 0;       // writing the recording
  double process_ms = 0;    // making the clip (last attempt)
  int attempts = 0;         // processing attempts started (not those a shutdown or a full disk cut short)
  int worker_crashes = 0;   // attempts whose worker process died by a signal or was killed for a limit
  std::string error;        // why it failed: a Status::ToString()
  std::string note;         // a short human summary of the last step ("90 frames, 9 views")
  // The settings the press was made with (device/press_settings.h); "" = the config's clip.*.
  std::string move;
  std::string effect;
  std::string format;
  std::string size;
  std::string shot;  // the shot (JSON text) asked for at the press (set_shot); "" = none
};

nlohmann::json JobRecordToJson(const JobRecord& record);
// `what` names the record in errors ("/var/lib/parallax/jobs/000042.json").
StatusOr<JobRecord> JobRecordFromJson(const nlohmann::json& j, const std::string& what);

// ISO 8601 UTC with milliseconds: "2024-05-01T12:03:04.123Z".
std::string NowIso8601Utc();

// Thread-safe. Records live in memory and on disk; Put writes through before returning.
class JobJournal {
 public:
  // Loads every <id>.json under `jobs_dir`. Unreadable records are renamed to <id>.json.corrupt
  // (kept for inspection) and reported through a warning log, never fatal.
  static StatusOr<std::unique_ptr<JobJournal>> Open(const std::filesystem::path& jobs_dir);

  // Writes the record atomically, then updates memory. On error memory keeps the old record.
  Status Put(const JobRecord& record);
  std::optional<JobRecord> Get(const std::string& id) const;
  std::vector<JobRecord> List() const;  // in id (press) order
  // Deletes the record's file (the folder fsynced), then forgets it; NOT_FOUND for an unknown id.
  // Its id is never given out again by this journal.
  Status Remove(const std::string& id);

  // A fresh id, greater than every id in the journal and every name in `also_taken`
  // (e.g. folders under captures/ whose journal records were lost).
  std::string NewId(const std::vector<std::string>& also_taken = {});

 private:
  explicit JobJournal(std::filesystem::path jobs_dir) : jobs_dir_(std::move(jobs_dir)) {}

  std::filesystem::path jobs_dir_;
  mutable std::mutex mutex_;
  std::map<std::string, JobRecord> records_;
  uint64_t next_sequence_ = 1;
};

}  // namespace px::device
