#include "device/preview/preview_session.h"

#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "device/preview/preview_protocol.h"
#include "device/worker/spawn_child.h"
#include "device/worker/write_all.h"
#include "pipeline/core/log.h"

namespace px::device {

namespace {

std::string ErrnoMessage(int err) { return std::strerror(err); }

// A worker's error reply as a status with its code.
Status StatusFromReply(const nlohmann::json& reply) {
  const std::string code = reply.value("code", "INTERNAL");
  const std::string message = reply.value("message", "preview worker failed");
  const std::optional<StatusCode> parsed = StatusCodeFromName(code);
  return Status(parsed.value_or(StatusCode::kInternal), message);
}

}  // namespace

StatusOr<std::unique_ptr<PreviewSession>> PreviewSession::Open(const PreviewOptions& options,
                                                               const std::filesystem::path& capture_dir) {
  int request_pipe[2];
  int reply_pipe[2];
  if (::pipe2(request_pipe, O_CLOEXEC) != 0) return InternalError("preview pipes: " + ErrnoMessage(errno));
  if (::pipe2(reply_pipe, O_CLOEXEC) != 0) {
    ::close(request_pipe[0]);
    ::close(request_pipe[1]);
    return InternalError("preview pipes: " + ErrnoMessage(errno));
  }
  StatusOr<pid_t> pid =
      SpawnDaemonChild(options.binary, kPreviewWorkerFlag, {{0, request_pipe[0]}, {kPreviewMessageFd, reply_pipe[1]}});
  ::close(request_pipe[0]);
  ::close(reply_pipe[1]);
  auto session = std::unique_ptr<PreviewSession>(new PreviewSession());
  session->options_ = options;
  session->request_fd_ = request_pipe[1];
  session->reply_fd_ = reply_pipe[0];
  if (!pid.ok()) return pid.status();
  session->pid_ = *pid;
  std::lock_guard<std::mutex> lock(session->mutex_);
  PX_RETURN_IF_ERROR(session->Send({{"capture_dir", capture_dir.string()}, {"config", options.config}}));
  PX_ASSIGN_OR_RETURN(nlohmann::json reply, session->ReadReply(options.load_timeout));
  if (!reply.value("ok", false)) return StatusFromReply(reply);
  session->scene_ = reply["scene"];
  return session;
}

PreviewSession::~PreviewSession() {
  if (request_fd_ >= 0) ::close(request_fd_);  // the worker's end of input: it exits
  if (reply_fd_ >= 0) ::close(reply_fd_);
  if (pid_ > 0) {
    // A worker busy on a frame gets a moment to notice, then is killed.
    for (int i = 0; i < 20; ++i) {
      if (::waitpid(pid_, nullptr, WNOHANG) == pid_) return;
      ::usleep(10000);
    }
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
  }
}

void PreviewSession::Kill() {
  dead_ = true;
  if (pid_ > 0) ::kill(pid_, SIGKILL);
}

PreviewSession::Clock::time_point PreviewSession::last_used() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_used_;
}

Status PreviewSession::Send(const nlohmann::json& request) {
  const std::string line = request.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  // A worker that died is an error for this session (EPIPE), not the daemon's end (SIGPIPE).
  if (dead_) return UnavailableError("the preview worker is gone; the preview opens again on the next request");
  const int error = WriteAll(request_fd_, line);
  if (error == 0) return OkStatus();
  dead_ = true;
  return UnavailableError("the preview worker is gone: " + ErrnoMessage(error));
}

StatusOr<bool> PreviewSession::Fill(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  if (left <= 0) {
    // Its late answer would be read as the next request's: the worker ends with this preview.
    Kill();
    return DeadlineExceededError("the preview worker did not answer in time; killed");
  }
  if (options_.memory_limit_bytes > 0) {
    // Looked at while the worker works (building a scene takes seconds): a preview that would
    // take the device's memory ends before the kernel's OOM killer picks a victim.
    if (const uint64_t resident = ResidentBytes(pid_); resident > options_.memory_limit_bytes) {
      Kill();
      return AbortedError("the preview worker used " + MegaBytes(resident) + ", over its limit of " +
                          MegaBytes(options_.memory_limit_bytes) + " (worker.memory_limit_mb); killed");
    }
  }
  pollfd fd{reply_fd_, POLLIN, 0};
  const int ready = ::poll(&fd, 1, static_cast<int>(std::min<long long>(left, 200)));
  if (ready < 0 && errno != EINTR) return InternalError("poll: " + ErrnoMessage(errno));
  if (ready <= 0) return false;
  char chunk[65536];
  const ssize_t n = ::read(reply_fd_, chunk, sizeof(chunk));
  if (n < 0 && errno == EINTR) return false;
  if (n <= 0) {
    dead_ = true;
    return UnavailableError("the preview worker ended (it may have crashed; see the log)");
  }
  buffer_.append(chunk, static_cast<size_t>(n));
  return true;
}

StatusOr<nlohmann::json> PreviewSession::ReadReply(std::chrono::milliseconds timeout) {
  const Clock::time_point deadline = Clock::now() + timeout;
  size_t newline;
  while ((newline = buffer_.find('\n')) == std::string::npos) PX_RETURN_IF_ERROR(Fill(deadline).status());
  nlohmann::json reply = nlohmann::json::parse(buffer_.substr(0, newline), nullptr, /*allow_exceptions=*/false);
  buffer_.erase(0, newline + 1);
  if (!reply.is_object()) return DataLossError("the preview worker's reply is not a JSON object");
  return reply;
}

StatusOr<std::string> PreviewSession::ReadBytes(size_t size, std::chrono::milliseconds timeout) {
  const Clock::time_point deadline = Clock::now() + timeout;
  while (buffer_.size() < size) PX_RETURN_IF_ERROR(Fill(deadline).status());
  std::string bytes = buffer_.substr(0, size);
  buffer_.erase(0, size);
  return bytes;
}

StatusOr<PreviewSession::BytesReply> PreviewSession::AskBytes(const nlohmann::json& request,
                                                              std::chrono::milliseconds timeout,
                                                              uint64_t max_bytes,
                                                              const std::string& what) {
  std::lock_guard<std::mutex> lock(mutex_);
  last_used_ = Clock::now();
  PX_RETURN_IF_ERROR(Send(request));
  PX_ASSIGN_OR_RETURN(nlohmann::json reply, ReadReply(timeout));
  if (!reply.value("ok", false)) return StatusFromReply(reply);
  const uint64_t size = reply.value("bytes", uint64_t{0});
  if (size == 0 || size > max_bytes) {
    // Its bytes would be read as the next request's answer: the worker ends with this preview.
    Kill();
    return DataLossError("the preview worker announced " + what + " of " + std::to_string(size) + " bytes (at most " +
                         std::to_string(max_bytes) + "); killed");
  }
  BytesReply out;
  PX_ASSIGN_OR_RETURN(out.bytes, ReadBytes(size, timeout));
  reply.erase("ok");
  reply.erase("bytes");
  out.reply = std::move(reply);
  return out;
}

StatusOr<PreviewFrame> PreviewSession::Frame(const nlohmann::json& viewpoint,
                                             bool coverage,
                                             bool draft,
                                             bool lossless) {
  PX_ASSIGN_OR_RETURN(BytesReply reply,
                      AskBytes({{"frame", viewpoint}, {"coverage", coverage}, {"draft", draft}, {"lossless", lossless}},
                               options_.frame_timeout,
                               kMaxFrameBytes,
                               "a frame"));
  PreviewFrame frame;
  frame.image = std::move(reply.bytes);
  frame.mime = lossless ? "image/png" : "image/jpeg";
  frame.figures = std::move(reply.reply);
  return frame;
}

StatusOr<std::string> PreviewSession::SceneExport() {
  // Made from the scene in memory: a second or so, sent at pipe speed.
  PX_ASSIGN_OR_RETURN(BytesReply reply,
                      AskBytes({{"scene_export", true}}, options_.load_timeout, kMaxSceneBytes, "a scene"));
  return std::move(reply.bytes);
}

StatusOr<nlohmann::json> PreviewSession::Ask(const nlohmann::json& request, std::chrono::milliseconds timeout) {
  std::lock_guard<std::mutex> lock(mutex_);
  last_used_ = Clock::now();
  PX_RETURN_IF_ERROR(Send(request));
  PX_ASSIGN_OR_RETURN(nlohmann::json reply, ReadReply(timeout));
  if (!reply.value("ok", false)) return StatusFromReply(reply);
  reply.erase("ok");
  return reply;
}

StatusOr<nlohmann::json> PreviewSession::Probe(const nlohmann::json& viewpoint, int x, int y) {
  return Ask({{"probe", viewpoint}, {"x", x}, {"y", y}}, options_.frame_timeout);
}

StatusOr<nlohmann::json> PreviewSession::Region(const nlohmann::json& viewpoint, const nlohmann::json& rect) {
  return Ask({{"region", viewpoint}, {"rect", rect}}, options_.frame_timeout);
}

StatusOr<nlohmann::json> PreviewSession::Map(const nlohmann::json& viewpoint, int cells) {
  // Up to 32 x 32 probes: as long as building the scene may take, not one frame.
  return Ask({{"map", viewpoint}, {"cells", cells}}, options_.load_timeout);
}

StatusOr<std::shared_ptr<PreviewSession>> PreviewSessions::ForJob(const std::string& job_id,
                                                                  const std::filesystem::path& capture_dir) {
  CloseIdle();
  if (auto open = Find(job_id)) return open;
  std::lock_guard<std::mutex> opening(open_mutex_);
  if (auto open = Find(job_id)) return open;  // opened while this request waited
  {
    // Room for one more: the least recently used goes.
    std::lock_guard<std::mutex> lock(mutex_);
    while (static_cast<int>(sessions_.size()) >= options_.max_sessions) {
      auto oldest = sessions_.begin();
      for (auto it = sessions_.begin(); it != sessions_.end(); ++it) {
        if (it->second->last_used() < oldest->second->last_used()) oldest = it;
      }
      Logger("device")->info("preview of job {} closed for a new one", oldest->first);
      sessions_.erase(oldest);
    }
  }
  Logger("device")->info("preview of job {}: building its scene", job_id);
  PX_ASSIGN_OR_RETURN(std::unique_ptr<PreviewSession> opened, PreviewSession::Open(options_, capture_dir));
  std::shared_ptr<PreviewSession> session = std::move(opened);
  std::lock_guard<std::mutex> lock(mutex_);
  sessions_[job_id] = session;
  return session;
}

std::shared_ptr<PreviewSession> PreviewSessions::Find(const std::string& job_id) {
  std::shared_ptr<PreviewSession> gone;  // ended outside the lock
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = sessions_.find(job_id);
  if (it == sessions_.end()) return nullptr;
  if (!it->second->alive()) {
    Logger("device")->info("preview of job {}: its worker is gone; opened again on the next request", job_id);
    gone = std::move(it->second);
    sessions_.erase(it);
    return nullptr;
  }
  return it->second;
}

void PreviewSessions::Close(const std::string& job_id) {
  std::shared_ptr<PreviewSession> closing;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = sessions_.find(job_id);
    if (it == sessions_.end()) return;
    closing = std::move(it->second);
    sessions_.erase(it);
  }
}

void PreviewSessions::CloseIdle() {
  std::vector<std::shared_ptr<PreviewSession>> closing;  // ended outside the lock
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto it = sessions_.begin(); it != sessions_.end();) {
    if (PreviewSession::Clock::now() - it->second->last_used() > options_.idle_limit) {
      Logger("device")->info("preview of job {} closed after {} s idle", it->first, options_.idle_limit.count());
      closing.push_back(std::move(it->second));
      it = sessions_.erase(it);
    } else {
      ++it;
    }
  }
}

void PreviewSessions::CloseAll() {
  std::lock_guard<std::mutex> lock(mutex_);
  sessions_.clear();
}

}  // namespace px::device
