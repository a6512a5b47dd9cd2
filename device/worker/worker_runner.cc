#include "device/worker/worker_runner.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "device/worker/spawn_child.h"
#include "device/worker/worker_protocol.h"
#include "device/worker/write_all.h"
#include "pipeline/core/log.h"
#include "pipeline/core/unique_fd.h"

namespace px::device {
namespace {

using Clock = std::chrono::steady_clock;

std::string ErrnoText(int err) { return std::strerror(err); }

std::string SignalName(int signal) {
  const char* abbrev = ::sigabbrev_np(signal);
  return abbrev != nullptr ? std::string("SIG") + abbrev : "signal " + std::to_string(signal);
}

// Writes all of `bytes` to a pipe whose reader may already be gone (EPIPE, never SIGPIPE).
Status WriteToPipe(int fd, const std::string& bytes) {
  const int error = WriteAll(fd, bytes);
  return error == 0 ? OkStatus() : InternalError("writing the worker's request: " + ErrnoText(error));
}

// Starts `binary --job-worker` with `request_fd` as its stdin and `message_fd` as fd 3.
StatusOr<pid_t> SpawnWorker(const std::filesystem::path& binary, int request_fd, int message_fd) {
  return SpawnDaemonChild(binary, kJobWorkerFlag, {{0, request_fd}, {kWorkerMessageFd, message_fd}});
}

// Why the runner killed the worker, if it did.
enum class KillReason { kNone, kCancel, kMemory, kTimeout };

class WorkerSupervisor {
 public:
  WorkerSupervisor(const WorkerRunnerOptions& options, const JobContext& context)
      : options_(options), context_(context) {}

  StatusOr<JobOutcome> Run() {
    int request_pipe[2];
    int message_pipe[2];
    if (::pipe2(request_pipe, O_CLOEXEC) != 0 || ::pipe2(message_pipe, O_CLOEXEC) != 0) {
      return InternalError("pipes for the job worker: " + ErrnoText(errno));
    }
    UniqueFd request_read(request_pipe[0]);
    UniqueFd request_write(request_pipe[1]);
    UniqueFd message_read(message_pipe[0]);
    UniqueFd message_write(message_pipe[1]);
    PX_ASSIGN_OR_RETURN(pid_, SpawnWorker(options_.binary, request_read.get(), message_write.get()));
    request_read.Close();
    message_write.Close();  // the worker holds the only write end: its exit is our end of file
    started_ = Clock::now();
    if (context_.worker) context_.worker(pid_);
    Logger("device")->info("job {}: worker {} started", context_.job_id, pid_);

    WorkerRequest request{
        context_.job_id, context_.capture_dir, context_.clip_path, context_.settings, context_.shot, options_.config};
    // A worker that dies before reading its request shows as its exit status below.
    (void)WriteToPipe(request_write.get(), WorkerRequestToJson(request).dump() + "\n");
    request_write.Close();

    Supervise(message_read.get());
    int wait_status = 0;
    rusage usage{};
    while (::wait4(pid_, &wait_status, 0, &usage) < 0 && errno == EINTR) {
    }
    if (context_.worker) context_.worker(0);
    const uint64_t peak = static_cast<uint64_t>(usage.ru_maxrss) * 1024;
    StatusOr<JobOutcome> outcome = Outcome(wait_status);
    Logger("device")->info("job {}: worker {} ended after {:.1f} s, peak memory {} ({})",
                           context_.job_id,
                           pid_,
                           std::chrono::duration<double>(Clock::now() - started_).count(),
                           MegaBytes(peak),
                           outcome.ok() ? "clip made" : outcome.status().ToString());
    return outcome;
  }

 private:
  // Reads progress and the result until the worker closes its end; enforces the limits.
  void Supervise(int fd) {
    std::string pending;
    char buffer[4096];
    while (true) {
      pollfd poll_fd{fd, POLLIN, 0};
      const int ready = ::poll(&poll_fd, 1, 100);
      if (ready < 0 && errno != EINTR) break;
      if (ready > 0) {
        const ssize_t n = ::read(fd, buffer, sizeof(buffer));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;  // end of file: the worker exited (or closed fd 3, and will)
        pending.append(buffer, static_cast<size_t>(n));
        for (size_t end; (end = pending.find('\n')) != std::string::npos; pending.erase(0, end + 1)) {
          HandleLine(std::string_view(pending).substr(0, end));
        }
      }
      EnforceLimits();
    }
  }

  void HandleLine(std::string_view line) {
    StatusOr<WorkerLine> parsed = ParseWorkerLine(line);
    if (!parsed.ok()) {
      Logger("device")->warn("job {}: worker {}: {}", context_.job_id, pid_, parsed.status().message());
      return;
    }
    if (parsed->result) {
      result_ = std::move(parsed->result);
      return;
    }
    stage_ = parsed->stage;
    fraction_ = parsed->fraction;
    if (context_.progress && !context_.progress(parsed->stage, parsed->fraction)) AskToStop();
  }

  void AskToStop() {
    if (kill_reason_ != KillReason::kNone || stop_asked_) return;
    stop_asked_ = true;
    stop_deadline_ = Clock::now() + options_.cancel_grace;
    ::kill(pid_, SIGTERM);
  }

  void EnforceLimits() {
    if (kill_reason_ != KillReason::kNone) return;
    const Clock::time_point now = Clock::now();
    // The daemon may want the job stopped while the worker is busy between progress reports.
    if (!stop_asked_ && context_.progress && !context_.progress(stage_.empty() ? "start" : stage_, fraction_)) {
      AskToStop();
    }
    if (stop_asked_ && now > stop_deadline_) {
      Kill(KillReason::kCancel);
      return;
    }
    if (now - started_ > options_.timeout) {
      Kill(KillReason::kTimeout);
      return;
    }
    if (options_.memory_limit_bytes > 0) {
      resident_ = ResidentBytes(pid_);
      if (resident_ > options_.memory_limit_bytes) Kill(KillReason::kMemory);
    }
  }

  void Kill(KillReason reason) {
    kill_reason_ = reason;
    ::kill(pid_, SIGKILL);
  }

  std::string During() const { return stage_.empty() ? "before its first stage" : "during " + stage_; }

  StatusOr<JobOutcome> Outcome(int wait_status) const {
    switch (kill_reason_) {
      case KillReason::kCancel:
        return CancelledError("the worker did not stop within " + std::to_string(options_.cancel_grace.count() / 1000) +
                              " s of being asked " + During() + "; killed");
      case KillReason::kMemory:
        return AbortedError("the worker used " + MegaBytes(resident_) + ", over its limit of " +
                            MegaBytes(options_.memory_limit_bytes) + " (worker.memory_limit_mb), " + During() +
                            "; killed");
      case KillReason::kTimeout:
        return AbortedError("the worker ran past its limit of " + std::to_string(options_.timeout.count()) +
                            " s (worker.timeout_s) " + During() + "; killed");
      case KillReason::kNone:
        break;
    }
    if (WIFSIGNALED(wait_status)) {
      return AbortedError("the worker was killed by " + SignalName(WTERMSIG(wait_status)) + " " + During());
    }
    if (result_) return *result_;
    const int code = WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : -1;
    return AbortedError("the worker exited with code " + std::to_string(code) + " " + During() + " without a result");
  }

  const WorkerRunnerOptions& options_;
  const JobContext& context_;
  pid_t pid_ = -1;
  Clock::time_point started_;
  std::string stage_;  // the worker's last progress report
  double fraction_ = 0;
  std::optional<StatusOr<JobOutcome>> result_;
  bool stop_asked_ = false;
  Clock::time_point stop_deadline_;
  KillReason kill_reason_ = KillReason::kNone;
  uint64_t resident_ = 0;
};

}  // namespace

uint64_t DefaultWorkerMemoryLimit() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  uint64_t kilobytes = 0;
  std::string unit;
  while (meminfo >> key >> kilobytes >> unit) {
    if (key == "MemTotal:") return kilobytes * 1024 / 4 * 3;
  }
  return 0;  // unknown: no limit rather than a wrong one
}

JobRunner MakeWorkerJobRunner(WorkerRunnerOptions options) {
  return [options = std::move(options)](const JobContext& context) -> StatusOr<JobOutcome> {
    return WorkerSupervisor(options, context).Run();
  };
}

}  // namespace px::device
