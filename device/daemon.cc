#include "device/daemon.h"

#include <algorithm>
#include <exception>
#include <system_error>

#include "capture/recording.h"
#include "device/clip_fetch.h"
#include "device/control/control_protocol.h"
#include "device/storage/storage_quota.h"
#include "device/test_pause.h"
#include "pipeline/core/json_fields.h"
#include "pipeline/core/log.h"
#include "pipeline/direct/direct_options.h"
#include "pipeline/direct/shot_file.h"
#include "pipeline/io/durable_file.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// One reply line; invalid UTF-8 (from a file name, say) is replaced rather than thrown.
std::string Dump(const nlohmann::json& j) { return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace); }

std::vector<std::string> NamesIn(const fs::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    names.push_back(it->path().stem().string());
  }
  return names;
}

}  // namespace

Status DaemonOptions::Validate() const {
  PX_RETURN_IF_ERROR(storage.Validate());
  if (capture_timeout.count() <= 0) {
    return InvalidArgumentError("capture_timeout: " + std::to_string(capture_timeout.count()) + " ms is not positive");
  }
  if (max_worker_crashes < 1) {
    return InvalidArgumentError("max_worker_crashes: " + std::to_string(max_worker_crashes) + " is below 1");
  }
  if (space_retry_interval.count() <= 0) return InvalidArgumentError("space_retry_interval: not above 0");
  return OkStatus();
}

Daemon::Daemon(DaemonOptions options, std::unique_ptr<FrameSource> source, JobRunner runner)
    : options_(std::move(options)),
      layout_(options_.storage.root),
      source_(std::move(source)),
      runner_(std::move(runner)) {
  PX_CHECK(source_ != nullptr) << "Daemon needs a FrameSource";
  PX_CHECK(runner_ != nullptr) << "Daemon needs a JobRunner";
}

Daemon::~Daemon() {
  bool running;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    running = started_ && !waited_;
  }
  if (running) {
    RequestStop(false);
    Wait();
  }
}

void Daemon::SetClipListener(std::function<void(const fs::path& clip)> listener) {
  clip_listener_ = std::move(listener);
}

void Daemon::SetEventListener(std::function<void(const nlohmann::json& event)> listener) {
  event_listener_ = std::move(listener);
}

Status Daemon::DeleteJob(const std::string& id) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::optional<JobRecord> record = journal_->Get(id);
  if (!record) return NotFoundError("job '" + id + "': no such job");
  if (!IsFinal(record->state) || id == capturing_id_ || id == processing_id_) {
    return FailedPreconditionError("job " + id + " is " + std::string(JobStateName(record->state)) +
                                   "; only a done or failed job can be deleted");
  }
  PX_RETURN_IF_ERROR(RemoveJobFiles(layout_, id, "delete"));
  PX_RETURN_IF_ERROR(journal_->Remove(id));
  Logger("device")->info("job {}: deleted on request (clip and raw capture removed)", id);
  if (event_listener_) event_listener_({{"type", "deleted"}, {"job", id}});
  return OkStatus();
}

void Daemon::SetStateListener(std::function<void(const std::string& state, bool stopping)> listener) {
  state_listener_ = std::move(listener);
}

Status Daemon::Start() {
  auto log = Logger("device");
  PX_RETURN_IF_ERROR(options_.Validate());
  PX_CHECK(!started_) << "Daemon::Start called twice";
  PX_RETURN_IF_ERROR(layout_.Prepare(options_.storage.group));
  PX_ASSIGN_OR_RETURN(journal_, JobJournal::Open(layout_.JobsDir()));
  if (StatusOr<PressSettings> saved = LoadPressSettings(layout_.SettingsPath()); saved.ok()) {
    settings_ = *saved;
    if (!settings_.Empty()) log->info("settings for the presses: {}", PressSettingsToJson(settings_).dump());
  } else {
    log->warn("{}; the presses use the config's clip settings", saved.status().ToString());
  }
  // Ids continue after any capture or clip whose journal record was lost.
  taken_ids_ = NamesIn(layout_.CapturesDir());
  for (std::string& name : NamesIn(layout_.ClipsDir())) taken_ids_.push_back(std::move(name));
  Recover();
  const size_t resumed = process_queue_.size();  // before the worker starts taking them

  if (Status configured = EnsureConfigured(); !configured.ok()) {
    log->error("{}; the daemon runs on and each press retries (and fails its job until the source answers)",
               configured.ToString());
  }

  if (!options_.control_socket.empty() || options_.trigger_fd >= 0 || !options_.loop_inputs.empty()) {
    ControlServer::Options server_options;
    server_options.socket_path = options_.control_socket;
    server_options.access = OwnerAccess(options_.control_group);
    server_options.trigger_fd = options_.trigger_fd;
    server_options.inputs = options_.loop_inputs;
    ControlServer::Handlers handlers;
    handlers.on_request = [this](const std::string& line, ControlServer::Respond respond) {
      HandleRequest(line, std::move(respond));
    };
    handlers.on_trigger = [this, log](const std::string&) {
      auto id = Press();
      if (!id.ok()) log->error("press from the trigger input refused: {}", id.status().ToString());
    };
    handlers.on_trigger_eof = [this, log] {
      log->info("trigger input closed; stopping once the queue is empty");
      std::lock_guard<std::mutex> lock(mutex_);
      trigger_open_ = false;
      if (!stopping_) {
        stopping_ = true;
        drain_ = true;
      }
      changed_.notify_all();
    };
    PX_ASSIGN_OR_RETURN(server_, ControlServer::Open(server_options, std::move(handlers)));
  }

  {
    std::lock_guard<std::mutex> lock(mutex_);
    started_ = true;
    trigger_open_ = options_.trigger_fd >= 0;
  }
  capture_thread_ = std::thread([this] { CaptureLoop(); });
  process_thread_ = std::thread([this] { ProcessLoop(); });
  if (server_) server_->Start();

  std::lock_guard<std::mutex> lock(mutex_);
  log->info("ready: storage {}, control socket {}, trigger {}, source {}, {} job(s) to resume",
            layout_.root().string(),
            options_.control_socket.empty() ? "none" : options_.control_socket.string(),
            options_.trigger_fd >= 0 ? "fd " + std::to_string(options_.trigger_fd) : "none",
            source_model_.empty() ? std::string(source_->Name()) + " (not configured)" : source_model_,
            resumed);
  OnProgressLocked();
  return OkStatus();
}

void Daemon::Recover() {
  auto log = Logger("device");
  for (JobRecord record : journal_->List()) {
    switch (record.state) {
      case JobState::kDone:
      case JobState::kFailed:
        break;
      case JobState::kCapturing: {
        std::error_code ec;
        // WriteRecording writes manifest.json last: with it the capture is complete.
        if (fs::exists(layout_.CaptureDir(record.id) / "manifest.json", ec)) {
          log->warn("job {}: the capture was saved but not journaled before the daemon stopped; resuming", record.id);
          record.state = JobState::kSaved;
          record.capture_dir = layout_.CaptureDir(record.id).string();
          record.updated_at = NowIso8601Utc();
          Record(record);
          process_queue_.push_back(record.id);
        } else {
          // A folder without manifest.json is an unfinished write (WriteRecording removes those
          // itself when it fails); remove it as that would have.
          std::error_code removed;
          const bool partial = fs::remove_all(layout_.CaptureDir(record.id), removed) > 0;
          FailJob(record,
                  UnavailableError(partial ? "the daemon stopped while the capture was being written; the "
                                             "unfinished recording was removed"
                                           : "the daemon stopped before the capture was saved"),
                  "capture");
        }
        break;
      }
      case JobState::kProcessing:
        // The daemon stopped (killed, power lost) while the job's worker ran: not the job's
        // fault, so it resumes however often that happened. Crashes of the worker itself are
        // counted as they happen (ProcessJob).
        log->warn("job {}: the daemon stopped while it was being processed (attempt {}); resuming",
                  record.id,
                  record.attempts);
        record.state = JobState::kSaved;
        record.updated_at = NowIso8601Utc();
        Record(record);
        process_queue_.push_back(record.id);
        break;
      case JobState::kSaved:
        log->info("job {}: resuming saved capture", record.id);
        process_queue_.push_back(record.id);
        break;
    }
  }
}

StatusOr<std::string> Daemon::Press() {
  auto log = Logger("device");
  std::lock_guard<std::mutex> lock(mutex_);
  if (!started_) return FailedPreconditionError("daemon not started; press ignored");
  if (stopping_) return FailedPreconditionError("daemon is shutting down; press ignored");
  // A press the store has no room for, even after evicting what may be evicted, is refused before
  // it is acknowledged: the user learns at once, and no job is made that can only fail.
  if (StatusOr<StorageUsage> usage = MeasureStorage(layout_, options_.storage, *journal_); usage.ok() && usage->full) {
    log->error("press refused before acknowledgement: {}", usage->shortfall.message());
    return Status(usage->shortfall.code(), "press refused: " + usage->shortfall.message());
  }
  JobRecord record;
  record.id = journal_->NewId(taken_ids_);
  taken_ids_.clear();
  record.state = JobState::kCapturing;
  record.move = settings_.move;
  record.effect = settings_.effect;
  record.format = settings_.format;
  record.size = settings_.size;
  record.shot = shot_;
  record.created_at = NowIso8601Utc();
  record.updated_at = record.created_at;
  // Journaled before it is acknowledged: an acknowledged press is never silently lost.
  Status journaled = journal_->Put(record);
  if (!journaled.ok()) {
    log->error("press refused: cannot journal job {}: {}", record.id, journaled.ToString());
    return journaled;
  }
  if (event_listener_) event_listener_({{"type", "job"}, {"job", JobRecordToJson(record)}});
  capture_queue_.push_back(record.id);
  log->info("job {}: pressed ({} waiting for capture, {} for processing)",
            record.id,
            capture_queue_.size(),
            process_queue_.size());
  OnProgressLocked();
  return record.id;
}

void Daemon::RequestStop(bool drain) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!stopping_) {
    stopping_ = true;
    drain_ = drain;
    Logger("device")->info("stopping {}", drain ? "once the queue is empty" : "after the current step");
  } else if (!drain && drain_) {
    drain_ = false;
    Logger("device")->info("stopping after the current step");
  }
  OnProgressLocked();  // tells the state listener; wakes the threads
}

void Daemon::Wait() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!started_ || waited_) return;
  }
  if (capture_thread_.joinable()) capture_thread_.join();
  if (process_thread_.joinable()) process_thread_.join();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto& [id, respond] : waiters_) {
      respond(ControlErrorReply(
          UnavailableError("the daemon stopped before job " + id + " finished; it resumes at the next start")));
    }
    waiters_.clear();
  }
  if (server_) {
    server_->Stop();
    server_.reset();
  }
  source_->Stop();
  int left = 0;
  for (const JobRecord& record : journal_->List()) left += record.state == JobState::kSaved ? 1 : 0;
  std::lock_guard<std::mutex> lock(mutex_);
  waited_ = true;
  Logger("device")->info("stopped ({} saved job(s) left for the next start)", left);
}

void Daemon::WaitUntilIdle() {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return IdleLocked() || (capture_done_ && process_done_); });
}

bool Daemon::IdleLocked() const {
  return capture_queue_.empty() && process_queue_.empty() && capturing_id_.empty() && processing_id_.empty();
}

// Queued work counts: a saved capture waiting for the worker is "processing", never "idle".
std::string Daemon::StateNameLocked() const {
  if (!capturing_id_.empty() || !capture_queue_.empty()) return "capturing";
  if (!processing_id_.empty() || !process_queue_.empty()) return "processing";
  return "idle";
}

void Daemon::OnProgressLocked() {
  if (options_.exit_when_idle && started_ && !trigger_open_ && !stopping_ && IdleLocked()) {
    Logger("device")->info("idle; exiting as asked (--exit-when-idle)");
    stopping_ = true;
    drain_ = true;
  }
  if (state_listener_) {
    const std::string state = StateNameLocked();
    if (state != reported_state_ || stopping_ != reported_stopping_) {
      reported_state_ = state;
      reported_stopping_ = stopping_;
      state_listener_(state, stopping_);
    }
  }
  if (event_listener_) {
    const std::string state = StateNameLocked();
    if (state != evented_state_ || stopping_ != evented_stopping_) {
      evented_state_ = state;
      evented_stopping_ = stopping_;
      event_listener_({{"type", "state"}, {"state", state}, {"stopping", stopping_}});
    }
  }
  changed_.notify_all();
}

void Daemon::AnswerWaitersLocked(const JobRecord& record) {
  auto range = waiters_.equal_range(record.id);
  for (auto it = range.first; it != range.second; ++it) {
    it->second(Dump({{"ok", true}, {"job", JobRecordToJson(record)}}));
  }
  waiters_.erase(range.first, range.second);
}

void Daemon::Record(const JobRecord& record) {
  Status status = journal_->Put(record);
  if (!status.ok()) {
    Logger("device")->error(
        "job {}: journal not updated to '{}': {}", record.id, JobStateName(record.state), status.ToString());
  }
  if (event_listener_) event_listener_({{"type", "job"}, {"job", JobRecordToJson(record)}});
}

JobRecord Daemon::FailJob(JobRecord record, const Status& status, const std::string& during) {
  record.state = JobState::kFailed;
  record.error = status.ToString();
  record.updated_at = NowIso8601Utc();
  Record(record);
  Logger("device")->error("job {}: {} failed: {}{}",
                          record.id,
                          during,
                          record.error,
                          record.capture_dir.empty() ? "" : " (raw capture kept at " + record.capture_dir + ")");
  return record;
}

Status Daemon::EnsureConfigured() {
  if (configured_) return OkStatus();
  auto log = Logger("device");
  const auto start = std::chrono::steady_clock::now();
  auto result = source_->Configure(options_.wanted_source.value_or(SourceConfig{}), &granted_);
  if (!result.ok()) return result.status().WithContext("configure source '" + std::string(source_->Name()) + "'");
  if (*result == ConfigureResult::kAdjusted && options_.wanted_source) {
    log->warn("source {} adjusted the configuration: wanted {}, granted {}",
              source_->Name(),
              DescribeConfig(*options_.wanted_source),
              DescribeConfig(granted_));
  }
  description_ = source_->Describe();
  configured_ = true;
  log->info(
      "source {} configured: {} in {:.0f} ms", description_.model, DescribeConfig(granted_), MillisecondsSince(start));
  std::lock_guard<std::mutex> lock(mutex_);
  source_model_ = description_.model;
  return OkStatus();
}

void Daemon::CaptureLoop() {
  while (true) {
    std::string id;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [this] { return !capture_queue_.empty() || stopping_; });
      // Acknowledged presses are captured even while stopping: the moment cannot be retaken.
      if (capture_queue_.empty()) break;
      id = capture_queue_.front();
      capture_queue_.pop_front();
      capturing_id_ = id;
    }
    std::optional<JobRecord> finished = CaptureJob(id);
    std::lock_guard<std::mutex> lock(mutex_);
    capturing_id_.clear();
    if (finished) AnswerWaitersLocked(*finished);
    OnProgressLocked();
  }
  std::lock_guard<std::mutex> lock(mutex_);
  capture_done_ = true;
  changed_.notify_all();
}

std::optional<JobRecord> Daemon::CaptureJob(const std::string& id) {
  auto log = Logger("device");
  std::optional<JobRecord> found = journal_->Get(id);
  PX_CHECK(found.has_value()) << "job " << id << " was queued without a journal record";
  JobRecord record = *found;

  // Evicts the oldest finished clips when the quota or the free-space floor asks (storage_quota.h).
  if (auto room = MakeRoomForCapture(layout_, options_.storage, journal_.get()); !room.ok()) {
    return FailJob(record, room.status(), "capture");
  }
  if (Status configured = EnsureConfigured(); !configured.ok()) {
    return FailJob(record, configured, "capture");
  }
  const auto capture_start = std::chrono::steady_clock::now();
  StatusOr<FrameSet> frames = source_->Next(options_.capture_timeout);
  record.capture_ms = MillisecondsSince(capture_start);
  if (!frames.ok()) {
    // A camera that went away must be configured again before the next capture.
    if (frames.status().code() == StatusCode::kUnavailable ||
        frames.status().code() == StatusCode::kFailedPrecondition) {
      configured_ = false;
    }
    return FailJob(record, frames.status().WithContext("source " + description_.model), "capture");
  }
  const Status usable = CheckFrameSet(granted_, &frames.value());
  PauseHereIfAsked("capture");
  log->info("job {}: captured {} frame(s), {} usable, {} in {:.0f} ms",
            id,
            frames->frames.size(),
            frames->NumUsableFrames(),
            DescribeConfig(granted_),
            record.capture_ms);

  // The raw capture goes to disk before anything else happens to it, even when parts are bad.
  Recording recording;
  recording.source = description_;
  recording.frames = std::move(frames).value();
  recording.created_by = options_.created_by;
  const fs::path capture_dir = layout_.CaptureDir(id);
  const auto save_start = std::chrono::steady_clock::now();
  auto pause_before_manifest = [](const fs::path& path) {
    if (path.filename() == "manifest.json") PauseHereIfAsked("writing_capture");
    return OkStatus();
  };
  if (Status saved = WriteRecording(capture_dir, recording, pause_before_manifest); !saved.ok()) {
    return FailJob(record, saved.WithContext("save capture"), "capture");
  }
  record.save_ms = MillisecondsSince(save_start);
  record.capture_dir = capture_dir.string();
  log->info("job {}: saved capture to {} in {:.0f} ms", id, record.capture_dir, record.save_ms);
  const int bad = static_cast<int>(recording.frames.frames.size()) - recording.frames.NumUsableFrames();
  if (bad > 0) {
    // Even with no frame as configured, the pipeline may honestly use part of one (the whole
    // tiles of a truncated frame, a frame in another format); if not, it fails naming the frame.
    record.note = std::to_string(bad) + " of " + std::to_string(recording.frames.frames.size()) + " frames unusable" +
                  (usable.ok() ? "" : " (" + usable.message() + ")");
    log->warn("job {}: {}; processing what can be used", id, record.note);
  }
  record.state = JobState::kSaved;
  record.updated_at = NowIso8601Utc();
  Record(record);
  PauseHereIfAsked("saved");
  std::lock_guard<std::mutex> lock(mutex_);
  process_queue_.push_back(id);
  OnProgressLocked();
  return std::nullopt;
}

void Daemon::ProcessLoop() {
  while (true) {
    std::string id;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      const auto ready = [this] {
        return (stopping_ && !drain_) || !process_queue_.empty() || (stopping_ && capture_done_);
      };
      if (waiting_for_space_.empty()) {
        changed_.wait(lock, ready);
      } else if (!changed_.wait_for(lock, options_.space_retry_interval, ready)) {
        RequeueIfRoomLocked();
        continue;
      }
      if (stopping_ && !drain_) break;
      if (process_queue_.empty()) break;  // stopping, captures finished, nothing left
      id = process_queue_.front();
      process_queue_.pop_front();
      processing_id_ = id;
      processing_stage_.clear();
      processing_fraction_ = 0;
      OnProgressLocked();
    }
    std::optional<JobRecord> finished = ProcessJob(id);
    std::lock_guard<std::mutex> lock(mutex_);
    processing_id_.clear();
    if (finished) AnswerWaitersLocked(*finished);
    OnProgressLocked();
  }
  std::lock_guard<std::mutex> lock(mutex_);
  process_done_ = true;
  changed_.notify_all();
}

namespace {

// A clip lost for want of disk space (ENOSPC, EDQUOT, or the free-space floor), not to the shot.
bool IsDiskFull(const Status& status) {
  if (status.code() != StatusCode::kResourceExhausted) return false;
  const std::string& message = status.message();
  return message.find("disk full") != std::string::npos || message.find("No space left") != std::string::npos ||
         message.find("quota exceeded") != std::string::npos;
}

}  // namespace

std::optional<JobRecord> Daemon::ProcessJob(const std::string& id) {
  auto log = Logger("device");
  std::optional<JobRecord> found = journal_->Get(id);
  PX_CHECK(found.has_value()) << "job " << id << " was queued without a journal record";
  JobRecord record = *found;
  record.state = JobState::kProcessing;
  record.attempts += 1;
  record.capture_dir = layout_.CaptureDir(id).string();
  record.updated_at = NowIso8601Utc();
  Record(record);

  JobContext context;
  context.job_id = id;
  context.capture_dir = layout_.CaptureDir(id);
  context.clip_path = layout_.ClipPath(id);
  context.settings = {record.move, record.effect, record.format, record.size};
  context.shot = record.shot;
  context.progress = [this, id](const std::string& stage, double fraction) {
    std::lock_guard<std::mutex> lock(mutex_);
    processing_stage_ = stage;
    processing_fraction_ = fraction;
    if (event_listener_) {
      event_listener_({{"type", "progress"}, {"job", id}, {"stage", stage}, {"progress", fraction}});
    }
    return !(stopping_ && !drain_) && cancel_id_ != id;
  };
  context.worker = [this](int pid) {
    std::lock_guard<std::mutex> lock(mutex_);
    processing_worker_pid_ = pid;
  };
  const auto start = std::chrono::steady_clock::now();
  StatusOr<JobOutcome> outcome = InternalError("job runner did not return");
  try {
    outcome = runner_(context);
  } catch (const std::exception& e) {  // a runner must not throw; keep the daemon up if one does
    outcome = InternalError(std::string("job runner threw: ") + e.what());
  }
  record.process_ms = MillisecondsSince(start);
  record.updated_at = NowIso8601Utc();
  std::string cancelled_during;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (cancel_id_ == id) {
      cancel_id_.clear();
      cancelled_during = processing_stage_.empty() ? "start" : processing_stage_;
    }
  }
  if (!cancelled_during.empty() && !outcome.ok()) {
    return FailJob(record,
                   CancelledError("cancelled by request during " + cancelled_during + "; raw capture kept at " +
                                  record.capture_dir),
                   "processing");
  }

  if (outcome.ok()) {
    PauseHereIfAsked("clip_written");
    record.state = JobState::kDone;
    if (!outcome->clip_path.empty()) context.clip_path = outcome->clip_path;
    record.clip_path = context.clip_path.string();
    record.note = outcome->note;
    record.error.clear();
    Record(record);
    log->info("job {}: clip {} ready in {:.1f} s ({})", id, record.clip_path, record.process_ms / 1000.0, record.note);
    if (clip_listener_) clip_listener_(context.clip_path);
    return record;
  }
  bool shutting_down;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    shutting_down = stopping_ && !drain_;
  }
  if (outcome.status().code() == StatusCode::kCancelled && shutting_down) {
    // Not the job's fault: back to saved, and the attempt does not count.
    record.state = JobState::kSaved;
    record.attempts -= 1;
    record.note = "interrupted by shutdown; resumes at the next start";
    Record(record);
    log->warn("job {}: processing interrupted by shutdown after {:.1f} s; it resumes at the next start",
              id,
              record.process_ms / 1000.0);
    return std::nullopt;
  }
  if (IsDiskFull(outcome.status())) {
    // Not the shot's fault: it waits, saved, for the store to have room again.
    record.state = JobState::kSaved;
    record.attempts -= 1;
    record.note = "waiting for free space: " + outcome.status().message() +
                  "; the clip is made once there is room (raw capture kept)";
    Record(record);
    log->warn("job {}: {}", id, record.note);
    std::lock_guard<std::mutex> lock(mutex_);
    waiting_for_space_.push_back(id);
    return std::nullopt;
  }
  if (outcome.status().code() == StatusCode::kAborted) return WorkerCrashed(std::move(record), outcome.status());
  return FailJob(record, outcome.status(), "processing");
}

std::optional<JobRecord> Daemon::WorkerCrashed(JobRecord record, const Status& crash) {
  auto log = Logger("device");
  // Only the worker wrote under clips/, and it died mid-write: its temporaries are garbage.
  if (int removed = RemoveStaleTemporaries(layout_.ClipsDir()); removed > 0) {
    log->info("job {}: removed {} temporary file(s) the worker left", record.id, removed);
  }
  record.worker_crashes += 1;
  if (record.worker_crashes >= options_.max_worker_crashes) {
    return FailJob(record,
                   AbortedError(crash.message() + "; failed after " + std::to_string(record.worker_crashes) +
                                " worker crash(es) on this job"),
                   "processing");
  }
  record.state = JobState::kSaved;
  record.note = "worker crash " + std::to_string(record.worker_crashes) + " of " +
                std::to_string(options_.max_worker_crashes) + ": " + crash.message() + "; retrying";
  Record(record);
  log->error("job {}: {}", record.id, record.note);
  std::lock_guard<std::mutex> lock(mutex_);
  process_queue_.push_back(record.id);  // behind jobs already waiting: a bad capture never blocks good ones
  return std::nullopt;
}

void Daemon::RequeueIfRoomLocked() {
  StatusOr<StorageUsage> usage = MeasureStorage(layout_, options_.storage, *journal_);
  if (!usage.ok() || usage->full) return;
  Logger("device")->info("the store has room again: {} job(s) waiting for free space go back to processing",
                         waiting_for_space_.size());
  for (std::string& id : waiting_for_space_) process_queue_.push_back(std::move(id));
  waiting_for_space_.clear();
  OnProgressLocked();
}

void Daemon::HandleRequest(const std::string& line, ControlServer::Respond respond) {
  auto log = Logger("device");
  StatusOr<ControlRequest> request = ParseControlRequest(line);
  if (!request.ok()) {
    log->warn("control: bad request: {}", request.status().message());
    respond(ControlErrorReply(request.status()));
    return;
  }
  switch (request->command) {
    case ControlCommand::kCapture: {
      StatusOr<std::string> id = Press();
      respond(id.ok() ? Dump({{"ok", true}, {"job", *id}}) : ControlErrorReply(id.status()));
      return;
    }
    case ControlCommand::kStatus:
      respond(Dump(StatusJson()));
      return;
    case ControlCommand::kList:
      respond(Dump(ListJson()));
      return;
    case ControlCommand::kWait: {
      std::lock_guard<std::mutex> lock(mutex_);
      std::optional<JobRecord> record = journal_->Get(request->job);
      if (!record) {
        respond(ControlErrorReply(NotFoundError("job '" + request->job + "': no such job")));
      } else if (IsFinal(record->state)) {
        respond(Dump({{"ok", true}, {"job", JobRecordToJson(*record)}}));
      } else if (process_done_) {
        respond(ControlErrorReply(
            UnavailableError("the daemon is stopping; job " + request->job + " resumes at the next start")));
      } else {
        waiters_.emplace(request->job, std::move(respond));
      }
      return;
    }
    case ControlCommand::kQuit:
      respond(Dump({{"ok", true}, {"stopping", true}, {"drain", request->drain}}));
      RequestStop(request->drain);
      return;
    case ControlCommand::kFetch:
      respond(FetchReply(request->job, request->inline_bytes));
      return;
    case ControlCommand::kSetMove:
      respond(SetMove(request->move));
      return;
    case ControlCommand::kSetSettings:
      respond(SetSettings(request->settings));
      return;
    case ControlCommand::kCancel:
      respond(Cancel(request->job));
      return;
    case ControlCommand::kSetShot:
      respond(SetShot(request->shot));
      return;
  }
}

nlohmann::json Daemon::StatusJson() const {
  std::vector<JobRecord> records = journal_->List();
  std::lock_guard<std::mutex> lock(mutex_);
  nlohmann::json counts = nlohmann::json::object();
  for (JobState state :
       {JobState::kCapturing, JobState::kSaved, JobState::kProcessing, JobState::kDone, JobState::kFailed}) {
    counts[std::string(JobStateName(state))] = 0;
  }
  for (const JobRecord& record : records) {
    counts[std::string(JobStateName(record.state))] = counts[std::string(JobStateName(record.state))].get<int>() + 1;
  }
  nlohmann::json j = {
      {"ok", true},
      {"state", StateNameLocked()},
      {"stopping", stopping_},
      {"root", layout_.root().string()},
      {"source", source_model_},
      {"queue", {{"capture", capture_queue_.size()}, {"process", process_queue_.size()}}},
      {"capturing", capturing_id_.empty() ? nlohmann::json(nullptr) : nlohmann::json(capturing_id_)},
      {"processing",
       processing_id_.empty()
           ? nlohmann::json(nullptr)
           : nlohmann::json(
                 {{"job", processing_id_},
                  {"stage", processing_stage_},
                  {"progress", processing_fraction_},
                  {"worker_pid",
                   processing_worker_pid_ == 0 ? nlohmann::json(nullptr) : nlohmann::json(processing_worker_pid_)}})},
      {"jobs", counts},
      {"last_job", records.empty() ? nlohmann::json(nullptr) : JobRecordToJson(records.back())},
      {"move", settings_.move.empty() ? nlohmann::json(nullptr) : nlohmann::json(settings_.move)},
      {"settings", PressSettingsToJson(settings_)},
      {"shot", shot_value_},
  };
  // Free space, quota and whether a capture would be refused now (disk full).
  StatusOr<StorageUsage> usage = MeasureStorage(layout_, options_.storage, *journal_);
  j["storage"] = usage.ok() ? StorageUsageToJson(*usage, options_.storage)
                            : nlohmann::json({{"full", true}, {"reason", usage.status().ToString()}});
  return j;
}

nlohmann::json Daemon::ListJson() const {
  nlohmann::json jobs = nlohmann::json::array();
  for (const JobRecord& record : journal_->List()) jobs.push_back(JobRecordToJson(record));
  return {{"ok", true}, {"jobs", jobs}};
}

std::optional<JobRecord> Daemon::Job(const std::string& id) const { return journal_->Get(id); }

std::string Daemon::FetchReply(const std::string& id, bool inline_bytes) const {
  StatusOr<nlohmann::json> reply = FetchClipReply(id, journal_->Get(id), inline_bytes, layout_);
  return reply.ok() ? Dump(*reply) : ControlErrorReply(reply.status());
}

std::string Daemon::SetMove(const std::string& move) {
  DirectOptions direct;
  direct.move = move;
  if (Status valid = direct.Validate(); !valid.ok()) return ControlErrorReply(valid);
  StatusOr<PressSettings> changed = ChangeSettings({{"move", move}});
  return changed.ok() ? Dump({{"ok", true}, {"move", move}}) : ControlErrorReply(changed.status());
}

std::string Daemon::SetSettings(const std::string& changes_json) {
  StatusOr<nlohmann::json> changes = json::Parse(changes_json, "settings");
  if (!changes.ok()) return ControlErrorReply(changes.status());
  StatusOr<PressSettings> changed = ChangeSettings(*changes);
  if (!changed.ok()) return ControlErrorReply(changed.status());
  return Dump({{"ok", true}, {"settings", PressSettingsToJson(*changed)}});
}

StatusOr<PressSettings> Daemon::ChangeSettings(const nlohmann::json& changes) {
  std::lock_guard<std::mutex> lock(mutex_);
  PX_ASSIGN_OR_RETURN(PressSettings updated, UpdatedPressSettings(settings_, changes));
  // Saved before it is answered: settings the page showed as saved survive a restart.
  PX_RETURN_IF_ERROR(SavePressSettings(layout_.SettingsPath(), updated).WithContext("settings not saved"));
  settings_ = updated;
  Logger("device")->info("settings for the next presses: {}", PressSettingsToJson(settings_).dump());
  return settings_;
}

namespace {

// A shot file's text checked as the pipeline will read it: its JSON and segment count.
StatusOr<std::pair<nlohmann::json, int>> CheckShot(const std::string& shot_json) {
  PX_ASSIGN_OR_RETURN(nlohmann::json j, json::Parse(shot_json, "shot"));
  PX_ASSIGN_OR_RETURN(direct::Shot shot, direct::ShotFromJson(j));
  return std::make_pair(std::move(j), static_cast<int>(shot.segments.size()));
}

// Links every file of `from` into `to` (a new folder), copying where a link cannot be made, via
// a temporary folder renamed into place: `to` appears complete or not at all.
Status LinkCapture(const fs::path& from, const fs::path& to) {
  const fs::path temp = to.parent_path() / ("." + to.filename().string() + ".tmp-link");
  std::error_code ec;
  fs::remove_all(temp, ec);
  fs::copy(from, temp, fs::copy_options::recursive | fs::copy_options::create_hard_links, ec);
  if (ec) {
    fs::remove_all(temp, ec);
    fs::copy(from, temp, fs::copy_options::recursive, ec);
    if (ec) return ErrnoToStatus(ec.value(), "copy capture", from);
  }
  PX_RETURN_IF_ERROR(FsyncDir(temp));
  return RenameDurably(temp, to);
}

}  // namespace

StatusOr<std::string> Daemon::RenderShot(const std::string& source_id, const std::string& shot_json) {
  auto log = Logger("device");
  PX_ASSIGN_OR_RETURN(auto checked, CheckShot(shot_json));
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopping_) return FailedPreconditionError("daemon is shutting down; render ignored");
  std::optional<JobRecord> source = journal_->Get(source_id);
  if (!source) return NotFoundError("job '" + source_id + "': no such job");
  std::error_code ec;
  if (source->state == JobState::kCapturing || source->capture_dir.empty() ||
      !fs::exists(fs::path(source->capture_dir) / "manifest.json", ec)) {
    return FailedPreconditionError("job " + source_id + " has no saved capture (" +
                                   (source->state == JobState::kCapturing ? "still capturing" : "evicted") + ")");
  }
  JobRecord record;
  record.id = journal_->NewId(taken_ids_);
  taken_ids_.clear();
  const fs::path capture_dir = layout_.CaptureDir(record.id);
  PX_RETURN_IF_ERROR(LinkCapture(source->capture_dir, capture_dir).WithContext("render shot"));
  record.state = JobState::kSaved;
  record.capture_dir = capture_dir.string();
  record.shot = shot_json;
  record.note = "authored shot of " + std::to_string(checked.second) + " segment(s) on the capture of job " + source_id;
  record.created_at = NowIso8601Utc();
  record.updated_at = record.created_at;
  Record(record);
  log->info("job {}: {}", record.id, record.note);
  process_queue_.push_back(record.id);
  OnProgressLocked();
  return record.id;
}

std::string Daemon::SetShot(const std::string& shot_json) {
  int segments = 0;
  nlohmann::json value;  // null: no shot
  if (!shot_json.empty()) {
    StatusOr<std::pair<nlohmann::json, int>> checked = CheckShot(shot_json);
    if (!checked.ok()) return ControlErrorReply(checked.status());
    value = std::move(checked->first);
    segments = checked->second;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  shot_ = shot_json;
  shot_value_ = value;
  if (shot_json.empty()) {
    Logger("device")->info("no shot for the next presses: the camera move decides");
    return Dump({{"ok", true}, {"shot", nullptr}});
  }
  Logger("device")->info("shot of {} segment(s) for the next presses", segments);
  return Dump({{"ok", true}, {"shot", value}, {"segments", segments}});
}

std::string Daemon::Cancel(const std::string& id) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::optional<JobRecord> record = journal_->Get(id);
  if (!record) return ControlErrorReply(NotFoundError("job '" + id + "': no such job"));
  const std::string was(JobStateName(record->state));
  auto take_from = [&](std::deque<std::string>* queue) {
    auto it = std::find(queue->begin(), queue->end(), id);
    if (it == queue->end()) return false;
    queue->erase(it);
    return true;
  };
  if (take_from(&capture_queue_)) {
    AnswerWaitersLocked(FailJob(*record, CancelledError("cancelled by request before the capture"), "capture"));
  } else if (take_from(&process_queue_)) {
    AnswerWaitersLocked(
        FailJob(*record,
                CancelledError("cancelled by request before processing; raw capture kept at " + record->capture_dir),
                "processing"));
  } else if (id == processing_id_) {
    cancel_id_ = id;  // the progress callback stops the pipeline; ProcessJob fails the job
    Logger("device")->info("job {}: cancelling the running clip", id);
  } else if (id == capturing_id_) {
    return ControlErrorReply(
        FailedPreconditionError("job " + id + " is being captured right now; cancel it once it is saved"));
  } else {
    return ControlErrorReply(FailedPreconditionError("job " + id + " is " + was + "; nothing to cancel"));
  }
  OnProgressLocked();
  return Dump({{"ok", true}, {"job", id}, {"was", was}});
}

}  // namespace px::device
