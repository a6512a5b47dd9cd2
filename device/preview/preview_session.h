// Authoring sessions' live previews, on the daemon's side: each session is a preview worker
// process (preview_worker.h) holding one capture's scene, asked for frames over pipes. A session
// builds its scene once (seconds: calibration and depth), then answers a frame in tens of
// milliseconds. Sessions idle longer than the idle limit are closed, and at most `max_sessions`
// live at once (the least recently used is closed for a new one): each holds a scene in memory.
#pragma once

#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace px::device {

struct PreviewOptions {
  std::filesystem::path binary;  // serves --preview-worker (parallaxd); "" = previews off
  nlohmann::json config;         // the daemon's effective config, handed to each worker
  int max_sessions = 2;
  std::chrono::seconds idle_limit{120};
  std::chrono::seconds load_timeout{300};  // building the scene
  std::chrono::seconds frame_timeout{20};  // one frame or probe
  // A worker whose resident memory passes this is killed, and its preview with it (the daemon
  // and the job worker go on); 0 = none. parallaxd gives it worker.memory_limit_mb's limit.
  uint64_t memory_limit_bytes = 0;
};

struct PreviewFrame {
  std::string image;  // JPEG, or PNG for a lossless frame
  std::string mime;
  nlohmann::json figures;  // render_ms, hole_ratio; h_v and valid when coverage was asked for
};

class PreviewSession {
 public:
  using Clock = std::chrono::steady_clock;
  // Starts a worker on `capture_dir` and waits until its scene is built. The worker's error
  // (a capture that cannot be calibrated: FAILED_PRECONDITION) comes back as it is.
  static StatusOr<std::unique_ptr<PreviewSession>> Open(const PreviewOptions& options,
                                                        const std::filesystem::path& capture_dir);
  ~PreviewSession();  // ends the worker (stdin closed, then SIGKILL) and reaps it

  const nlohmann::json& scene() const { return scene_; }
  // `coverage`: also measure H(V) there (an extra pass); `draft`: a frame of a drag, drawn at half
  // the size at most; `lossless`: PNG, not JPEG (for comparing the frame with another renderer's).
  // The figures hold the camera it was drawn with.
  StatusOr<PreviewFrame> Frame(const nlohmann::json& viewpoint,
                               bool coverage,
                               bool draft = false,
                               bool lossless = false);
  // The scene as a browser's renderer would draw it (pipeline/render/gl/web_scene.h).
  StatusOr<std::string> SceneExport();
  // The scene point under preview pixel (x, y): {"point_m": [...], "depth_m": d}.
  StatusOr<nlohmann::json> Probe(const nlohmann::json& viewpoint, int x, int y);
  // What the rectangle [x, y, w, h] of the preview covers: region_min_m, region_max_m, view, box_px.
  StatusOr<nlohmann::json> Region(const nlohmann::json& viewpoint, const nlohmann::json& rect);
  // H(V) over the plane the viewpoint's camera is dragged in: x_m, y_m (cells each), z_m, h_v
  // (rows of y, columns of x), valid_below.
  StatusOr<nlohmann::json> Map(const nlohmann::json& viewpoint, int cells);
  Clock::time_point last_used() const;
  // False once its worker is gone (crashed, or killed for a limit or a missed deadline): the
  // sessions then open the preview anew on its next request.
  bool alive() const { return !dead_.load(); }
  void Kill();  // ends the worker now (SIGKILL); the session is dead from then on

 private:
  struct BytesReply {
    nlohmann::json reply;  // without ok and bytes
    std::string bytes;
  };
  static constexpr uint64_t kMaxFrameBytes = 64u << 20;
  static constexpr uint64_t kMaxSceneBytes = 1024u << 20;

  PreviewSession() = default;
  // A request answered by a JSON line announcing `bytes`, then those bytes (at most max_bytes).
  StatusOr<BytesReply> AskBytes(const nlohmann::json& request,
                                std::chrono::milliseconds timeout,
                                uint64_t max_bytes,
                                const std::string& what);
  Status Send(const nlohmann::json& request);
  // A request answered by one JSON line within `timeout`.
  StatusOr<nlohmann::json> Ask(const nlohmann::json& request, std::chrono::milliseconds timeout);
  StatusOr<nlohmann::json> ReadReply(std::chrono::milliseconds timeout);
  StatusOr<std::string> ReadBytes(size_t size, std::chrono::milliseconds timeout);
  StatusOr<bool> Fill(std::chrono::steady_clock::time_point deadline);  // more bytes into buffer_

  PreviewOptions options_;
  pid_t pid_ = -1;
  int request_fd_ = -1;
  int reply_fd_ = -1;
  std::string buffer_;  // read from reply_fd_, not yet consumed
  nlohmann::json scene_;
  std::atomic<bool> dead_{false};
  mutable std::mutex mutex_;  // one request at a time
  Clock::time_point last_used_ = Clock::now();
};

// The sessions by job id. Thread-safe; a session being opened blocks only requests for it.
class PreviewSessions {
 public:
  explicit PreviewSessions(PreviewOptions options) : options_(std::move(options)) {}
  bool enabled() const { return !options_.binary.empty(); }
  // The job's session, opened on `capture_dir` when there is none.
  StatusOr<std::shared_ptr<PreviewSession>> ForJob(const std::string& job_id, const std::filesystem::path& capture_dir);
  // The job's session if it is open.
  std::shared_ptr<PreviewSession> Find(const std::string& job_id);
  void Close(const std::string& job_id);
  void CloseIdle();
  void CloseAll();

 private:
  PreviewOptions options_;
  std::mutex mutex_;
  std::map<std::string, std::shared_ptr<PreviewSession>> sessions_;
  std::mutex open_mutex_;  // one scene built at a time: two would halve each other's cores
};

}  // namespace px::device
