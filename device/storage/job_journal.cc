#include "device/storage/job_journal.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <nlohmann/json.hpp>
#include <system_error>

#include "pipeline/core/json_fields.h"
#include "pipeline/core/log.h"
#include "pipeline/io/durable_file.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;

constexpr int kIdDigits = 6;

std::string FormatId(uint64_t sequence) {
  std::string digits = std::to_string(sequence);
  if (digits.size() < kIdDigits) digits.insert(0, kIdDigits - digits.size(), '0');
  return digits;
}

}  // namespace

std::optional<uint64_t> ParseJobId(std::string_view id) {
  if (id.empty() || id.size() > 18) return std::nullopt;
  uint64_t value = 0;
  for (char c : id) {
    if (c < '0' || c > '9') return std::nullopt;
    value = value * 10 + static_cast<uint64_t>(c - '0');
  }
  return value;
}

std::string_view JobStateName(JobState state) {
  switch (state) {
    case JobState::kCapturing:
      return "capturing";
    case JobState::kSaved:
      return "saved";
    case JobState::kProcessing:
      return "processing";
    case JobState::kDone:
      return "done";
    case JobState::kFailed:
      return "failed";
  }
  return "unknown";
}

StatusOr<JobState> ParseJobState(std::string_view name) {
  for (JobState state :
       {JobState::kCapturing, JobState::kSaved, JobState::kProcessing, JobState::kDone, JobState::kFailed}) {
    if (JobStateName(state) == name) return state;
  }
  return InvalidArgumentError("'" + std::string(name) + "' is not one of capturing, saved, processing, done, failed");
}

bool IsFinal(JobState state) { return state == JobState::kDone || state == JobState::kFailed; }

std::string NowIso8601Utc() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t seconds = std::chrono::system_clock::to_time_t(now);
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  char buffer[96];
  std::snprintf(buffer,
                sizeof(buffer),
                "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ",
                utc.tm_year + 1900,
                utc.tm_mon + 1,
                utc.tm_mday,
                utc.tm_hour,
                utc.tm_min,
                utc.tm_sec,
                static_cast<int>(ms));
  return buffer;
}

nlohmann::json JobRecordToJson(const JobRecord& record) {
  nlohmann::json j = {
      {"id", record.id},
      {"state", std::string(JobStateName(record.state))},
      {"created_at", record.created_at},
      {"updated_at", record.updated_at},
      {"capture_dir", record.capture_dir},
      {"clip_path", record.clip_path},
      {"capture_ms", record.capture_ms},
      {"save_ms", record.save_ms},
      {"process_ms", record.process_ms},
      {"attempts", record.attempts},
      {"worker_crashes", record.worker_crashes},
      {"error", record.error},
      {"note", record.note},
      {"move", record.move},
      {"effect", record.effect},
      {"format", record.format},
      {"size", record.size},
      {"shot", record.shot},
  };
  return j;
}

StatusOr<JobRecord> JobRecordFromJson(const nlohmann::json& j, const std::string& what) {
  JobRecord record;
  PX_ASSIGN_OR_RETURN(record.id, json::GetString(j, "id", what));
  if (!ParseJobId(record.id)) return InvalidArgumentError(what + ".id: '" + record.id + "' is not a job id");
  PX_ASSIGN_OR_RETURN(std::string state, json::GetString(j, "state", what));
  auto parsed_state = ParseJobState(state);
  if (!parsed_state.ok()) return parsed_state.status().WithContext(what + ".state");
  record.state = *parsed_state;
  PX_ASSIGN_OR_RETURN(record.created_at, json::GetStringOr(j, "created_at", what, ""));
  PX_ASSIGN_OR_RETURN(record.updated_at, json::GetStringOr(j, "updated_at", what, ""));
  PX_ASSIGN_OR_RETURN(record.capture_dir, json::GetStringOr(j, "capture_dir", what, ""));
  PX_ASSIGN_OR_RETURN(record.clip_path, json::GetStringOr(j, "clip_path", what, ""));
  PX_ASSIGN_OR_RETURN(record.capture_ms, json::GetNumberOr(j, "capture_ms", what, 0));
  PX_ASSIGN_OR_RETURN(record.save_ms, json::GetNumberOr(j, "save_ms", what, 0));
  PX_ASSIGN_OR_RETURN(record.process_ms, json::GetNumberOr(j, "process_ms", what, 0));
  PX_ASSIGN_OR_RETURN(int64_t attempts, json::GetIntegerOr(j, "attempts", what, 0));
  record.attempts = static_cast<int>(attempts);
  PX_ASSIGN_OR_RETURN(int64_t worker_crashes, json::GetIntegerOr(j, "worker_crashes", what, 0));
  record.worker_crashes = static_cast<int>(worker_crashes);
  PX_ASSIGN_OR_RETURN(record.error, json::GetStringOr(j, "error", what, ""));
  PX_ASSIGN_OR_RETURN(record.note, json::GetStringOr(j, "note", what, ""));
  PX_ASSIGN_OR_RETURN(record.move, json::GetStringOr(j, "move", what, ""));
  PX_ASSIGN_OR_RETURN(record.effect, json::GetStringOr(j, "effect", what, ""));
  PX_ASSIGN_OR_RETURN(record.format, json::GetStringOr(j, "format", what, ""));
  PX_ASSIGN_OR_RETURN(record.size, json::GetStringOr(j, "size", what, ""));
  PX_ASSIGN_OR_RETURN(record.shot, json::GetStringOr(j, "shot", what, ""));
  return record;
}

StatusOr<std::unique_ptr<JobJournal>> JobJournal::Open(const fs::path& jobs_dir) {
  std::unique_ptr<JobJournal> journal(new JobJournal(jobs_dir));
  std::error_code ec;
  if (!fs::is_directory(jobs_dir, ec)) return NotFoundError(jobs_dir.string() + ": journal folder does not exist");
  auto log = Logger("device");
  for (fs::directory_iterator it(jobs_dir, ec), end; !ec && it != end; it.increment(ec)) {
    const fs::path& path = it->path();
    if (path.extension() != ".json" || IsTemporaryName(path.filename().string())) continue;
    StatusOr<JobRecord> record = [&]() -> StatusOr<JobRecord> {
      PX_ASSIGN_OR_RETURN(std::string text, ReadFileToString(path));
      PX_ASSIGN_OR_RETURN(nlohmann::json j, json::Parse(text, path.string()));
      PX_ASSIGN_OR_RETURN(JobRecord r, JobRecordFromJson(j, path.string()));
      if (r.id != path.stem().string()) {
        return InvalidArgumentError(path.string() + ".id: '" + r.id + "' does not match the file name");
      }
      return r;
    }();
    if (!record.ok()) {
      fs::path corrupt = path;
      corrupt += ".corrupt";
      std::error_code rename_ec;
      fs::rename(path, corrupt, rename_ec);
      log->warn("journal record unreadable, moved aside to {}: {}", corrupt.string(), record.status().ToString());
      continue;
    }
    journal->next_sequence_ = std::max(journal->next_sequence_, *ParseJobId(record->id) + 1);
    journal->records_[record->id] = std::move(record).value();
  }
  if (ec) return ErrnoToStatus(ec.value(), "list", jobs_dir);
  return journal;
}

Status JobJournal::Put(const JobRecord& record) {
  PX_CHECK(ParseJobId(record.id).has_value()) << "job id '" << record.id << "' was not made by NewId";
  const std::string text = JobRecordToJson(record).dump(2) + "\n";
  std::lock_guard<std::mutex> lock(mutex_);
  PX_RETURN_IF_ERROR(WriteFileAtomically(jobs_dir_ / (record.id + ".json"), text));
  records_[record.id] = record;
  return OkStatus();
}

Status JobJournal::Remove(const std::string& id) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (records_.find(id) == records_.end()) return NotFoundError("job '" + id + "': no such job");
  const fs::path path = jobs_dir_ / (id + ".json");
  std::error_code ec;
  fs::remove(path, ec);
  if (ec) return ErrnoToStatus(ec.value(), "remove", path);
  PX_RETURN_IF_ERROR(FsyncDir(jobs_dir_));
  records_.erase(id);
  return OkStatus();
}

std::optional<JobRecord> JobJournal::Get(const std::string& id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = records_.find(id);
  if (it == records_.end()) return std::nullopt;
  return it->second;
}

std::vector<JobRecord> JobJournal::List() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<JobRecord> records;
  records.reserve(records_.size());
  for (const auto& [id, record] : records_) records.push_back(record);
  // Ids are zero-padded, so name order is press order until a sequence outgrows the padding.
  std::stable_sort(records.begin(), records.end(), [](const JobRecord& a, const JobRecord& b) {
    return *ParseJobId(a.id) < *ParseJobId(b.id);
  });
  return records;
}

std::string JobJournal::NewId(const std::vector<std::string>& also_taken) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const std::string& name : also_taken) {
    if (auto sequence = ParseJobId(name)) next_sequence_ = std::max(next_sequence_, *sequence + 1);
  }
  return FormatId(next_sequence_++);
}

}  // namespace px::device
