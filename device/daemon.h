// The daemon: each press becomes a job that moves capturing -> saved -> processing -> done|failed
// (storage/job_journal.h). The raw capture is written durably as a recording BEFORE any
// processing, so a crash, a full disk or a pipeline failure never loses the shot. Presses are
// queued and never lost; a worker thread makes clips one at a time while presses keep coming.
// On start, jobs the journal shows as saved or processing are resumed (crash recovery).
#pragma once

#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "device/control/control_server.h"
#include "device/control/loop_input.h"
#include "device/press_settings.h"
#include "device/storage/job_journal.h"
#include "device/storage/storage_layout.h"
#include "drivers/source/frame_source.h"

namespace px::device {

struct DaemonOptions {
  StorageOptions storage;
  std::filesystem::path control_socket;  // empty: no socket
  std::optional<gid_t> control_group;    // members may use the socket too (0660); nullopt: owner only (0600)
  int trigger_fd = -1;                   // each line on this fd is a press (stdin: 0); EOF drains and stops
  // Stop once nothing is queued or running (after resuming leftover jobs). With a trigger fd,
  // only after its end of file: an open trigger means more presses may come.
  bool exit_when_idle = false;
  std::chrono::milliseconds capture_timeout{10000};  // one FrameSource::Next, > 0
  // What FrameSource::Configure asks for; nullopt: the source's native configuration.
  std::optional<SourceConfig> wanted_source;
  // More inputs for the control loop (an input-device button, the systemd watchdog); the loop
  // runs when there is a socket, a trigger fd or any of these.
  std::vector<std::shared_ptr<LoopInput>> loop_inputs;
  std::string created_by = "parallaxd";  // written into each recording
  // A job whose worker process crashes (a signal, or killed for a limit: JobRunner returns
  // ABORTED) this many times is failed; it is retried before that. The daemon being stopped or
  // killed never counts: its jobs resume at the next start. >= 1
  int max_worker_crashes = 3;
  // A job whose clip could not be written for want of disk space waits (saved, its attempt not
  // counted) and is processed again once the store has room, checked this often; > 0.
  std::chrono::milliseconds space_retry_interval{10000};
  Status Validate() const;
};

// What the job runner gets: where the capture is and where the clip must appear.
struct JobContext {
  std::string job_id;
  std::filesystem::path capture_dir;  // a complete recording
  std::filesystem::path clip_path;    // write atomically; nothing there on failure
  // stage: short name; fraction: 0..1 within it. Returns false when the daemon wants the job to
  // stop (shutdown, or a "cancel"): the runner should return CANCELLED soon.
  std::function<bool(const std::string& stage, double fraction)> progress;
  PressSettings settings;  // what the press asked for ("set_settings"); each "" = the runner's own
  std::string shot;        // the shot (JSON text, validated) asked for at the press ("set_shot"); "" = none
  // A runner that works in a child process tells its pid here when it starts, 0 when it has
  // ended (status shows it); may be empty.
  std::function<void(int pid)> worker;
};

struct JobOutcome {
  std::string note;  // one line for the log and the journal: "90 frames, 9 views, 1.2 MB"
  // Where the clip went, when the runner chose another name than JobContext::clip_path (another
  // clip format's extension); empty = that path.
  std::filesystem::path clip_path;
};

// Turns a saved capture into a clip. parallaxd runs RunClipJob (clip_job.h) in a worker process
// (worker/worker_runner.h); tests may pass a simpler real job. ABORTED means the work was killed
// from outside (a worker crash) and counts against max_worker_crashes.
using JobRunner = std::function<StatusOr<JobOutcome>(const JobContext&)>;

class Daemon {
 public:
  // `source` may fail to configure at Start: the daemon still starts (status, recovery) and
  // retries at each press, failing that press's job with the reason.
  Daemon(DaemonOptions options, std::unique_ptr<FrameSource> source, JobRunner runner);
  ~Daemon();  // RequestStop(false) and Wait() if still running

  // Prepares storage, opens the journal, resumes leftover jobs, configures the source, binds the
  // control socket and starts the threads. Fails on bad options, unusable storage or socket.
  Status Start();

  // One button press: a new job id, journaled as capturing, queued for capture.
  // FAILED_PRECONDITION while shutting down; the journal's write error otherwise.
  StatusOr<std::string> Press();

  // Stops accepting presses. Presses already acknowledged are still captured and saved.
  // drain=true: every queued job is processed first. drain=false: the job being processed is
  // cancelled and, like the queued ones, stays saved for the next start. Thread-safe.
  void RequestStop(bool drain);

  // Blocks until the daemon has stopped (after RequestStop, trigger EOF, "quit" or
  // exit_when_idle), then closes the control socket and the source.
  void Wait();

  // Blocks until nothing is queued, capturing or processing (for tests and tools).
  void WaitUntilIdle();

  // Called (on the worker thread) with each finished clip's absolute path. Set before Start.
  void SetClipListener(std::function<void(const std::filesystem::path& clip)> listener);
  // Called whenever the daemon's state ("idle", "capturing", "processing") or its stopping flag
  // changes, with the daemon's lock held: the listener must not call back into the daemon.
  // Set before Start. (systemd STATUS= and STOPPING=1.)
  void SetStateListener(std::function<void(const std::string& state, bool stopping)> listener);

  // Called with each event, as JSON, for the web app's live view (device/http/event_hub.h):
  //   {"type":"job","job":<record>}            every journal write (pressed, saved, done, failed)
  //   {"type":"progress","job":ID,"stage":S,"progress":F}   the processing job's stage and 0..1
  //   {"type":"state","state":S,"stopping":B}  as for the state listener
  // Possibly with the daemon's lock held: the listener must only queue the event. Set before Start.
  void SetEventListener(std::function<void(const nlohmann::json& event)> listener);

  // A new job that makes a clip of an earlier job's raw capture with `shot_json` (a shot file,
  // pipeline/direct/SHOT_FORMAT.md; the web app's authoring): the capture is linked into the new
  // job's folder (hard links: no second copy of the pixels), journaled as saved with the shot and
  // queued for processing. NOT_FOUND for an unknown job; FAILED_PRECONDITION when its capture is
  // not saved yet or was evicted; INVALID_ARGUMENT naming the field for a bad shot.
  StatusOr<std::string> RenderShot(const std::string& source_id, const std::string& shot_json);

  // Deletes a finished (done or failed) job: its clip, report, poster, preview, raw capture and
  // journal record. FAILED_PRECONDITION while it is still being captured or processed or waits
  // for either; NOT_FOUND for an unknown id.
  Status DeleteJob(const std::string& id);

  // One control request (a JSON line, device/control/control_protocol.h), answered exactly as on
  // the control socket; `respond` is called once, later for "wait". The web API goes through here.
  void HandleControlRequest(const std::string& line, ControlServer::Respond respond) {
    HandleRequest(line, std::move(respond));
  }

  nlohmann::json StatusJson() const;  // the reply to {"cmd":"status"}
  nlohmann::json ListJson() const;    // the reply to {"cmd":"list"}
  std::optional<JobRecord> Job(const std::string& id) const;
  const StorageLayout& layout() const { return layout_; }

 private:
  void HandleRequest(const std::string& line, ControlServer::Respond respond);
  void Recover();
  void CaptureLoop();
  void ProcessLoop();
  // Each returns the job's record when it reached done or failed (to answer "wait"s once the
  // job no longer shows as current), nullopt when it moved on to another queue.
  std::optional<JobRecord> CaptureJob(const std::string& id);
  // An ABORTED outcome: counts the crash, then queues the job again or fails it at the limit.
  std::optional<JobRecord> WorkerCrashed(JobRecord record, const Status& crash);
  void RequeueIfRoomLocked();  // waiting_for_space_ back to processing when the store has room
  std::optional<JobRecord> ProcessJob(const std::string& id);
  Status EnsureConfigured();
  // Writes the record; logs (never throws away) a journal write failure.
  void Record(const JobRecord& record);
  // Journals and logs the failure; returns the failed record.
  JobRecord FailJob(JobRecord record, const Status& status, const std::string& during);
  // Call with mutex_ held after any change to queues or current jobs.
  void OnProgressLocked();
  std::string StateNameLocked() const;
  bool IdleLocked() const;
  void AnswerWaitersLocked(const JobRecord& record);
  // The control commands "fetch", "set_move" and "cancel": the reply line.
  std::string FetchReply(const std::string& id, bool inline_bytes) const;
  std::string SetMove(const std::string& move);
  std::string SetSettings(const std::string& changes_json);
  // The settings with `changes` (UpdatedPressSettings) applied, saved and made the daemon's.
  StatusOr<PressSettings> ChangeSettings(const nlohmann::json& changes);
  std::string SetShot(const std::string& shot_json);
  std::string Cancel(const std::string& id);

  DaemonOptions options_;
  StorageLayout layout_;
  std::unique_ptr<FrameSource> source_;
  JobRunner runner_;
  std::function<void(const std::filesystem::path&)> clip_listener_;
  std::function<void(const std::string&, bool)> state_listener_;
  std::function<void(const nlohmann::json&)> event_listener_;
  std::string reported_state_;  // the last state given to state_listener_ (guarded by mutex_)
  bool reported_stopping_ = false;
  std::string evented_state_;  // the last state given to event_listener_ (guarded by mutex_)
  bool evented_stopping_ = false;
  std::unique_ptr<JobJournal> journal_;
  std::unique_ptr<ControlServer> server_;

  // Touched by the capture thread only (and Start before it runs).
  bool configured_ = false;
  SourceConfig granted_;
  SourceDescription description_;

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::string> capture_queue_;
  std::deque<std::string> process_queue_;
  std::vector<std::string> waiting_for_space_;  // saved jobs whose clip wait for disk space
  std::string capturing_id_;
  std::string processing_id_;
  std::string processing_stage_;
  int processing_worker_pid_ = 0;  // the job's worker process; 0 = none (or an in-process runner)
  std::string cancel_id_;          // the job being processed that a "cancel" asked to stop
  PressSettings settings_;         // from "set_settings" or "set_move", for jobs pressed after it
  std::string shot_;               // from "set_shot" (JSON text), for jobs pressed after it; "" = none
  nlohmann::json shot_value_;      // shot_ parsed once for status replies; null when none
  double processing_fraction_ = 0;
  std::string source_model_;
  bool started_ = false;
  bool stopping_ = false;
  bool drain_ = true;
  bool capture_done_ = false;  // the capture thread has exited
  bool process_done_ = false;  // the processing thread has exited
  bool trigger_open_ = false;
  bool waited_ = false;
  std::vector<std::string> taken_ids_;                          // names under captures/ and clips/, for the first NewId
  std::multimap<std::string, ControlServer::Respond> waiters_;  // job id -> "wait" replies
  std::thread capture_thread_;
  std::thread process_thread_;
};

}  // namespace px::device
