// The daemon's configuration: every field has a default, so an empty JSON object (or no file at
// all) is a working config. Lookup order (README "Configuration"): --config FILE, else the file
// named by $PARALLAX_CONFIG, else the built-in defaults; command-line overrides apply last.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <string>

#include "device/storage/storage_layout.h"
#include "pipeline/core/status.h"
#include "pipeline/direct/output_frame.h"
#include "sim/faults/fault_spec.h"

namespace px::device {

// The simulated lattice camera (sim/synthetic).
struct SimSourceSettings {
  std::filesystem::path scene;  // scene JSON (sim/scenes/*.json); empty = the synthetic source's default
  std::string camera = "pop9";  // preset: "pop9" (3x3, 640x480 tiles) or "integral5x4" (5x4, 320x240)
  int tile_width = 0;           // pixels per tile, 0 = the preset's; the focal length scales with it
  int tile_height = 0;          // 0 = the preset's
  uint64_t seed = 1;            // noise and exposure draws
};

// Recorded captures played back (sim/replay).
struct ReplaySourceSettings {
  std::filesystem::path path;  // one recording folder, or a folder of recordings
  bool loop = true;            // start again after the last recording
};

// A camera libcamera lists (drivers/libcamera).
struct LibcameraSourceSettings {
  std::string camera;                   // libcamera's camera id; "" = the first camera listed
  std::string pixel_format = "RGB888";  // px pixel format name (pipeline/core/pixel_format.h)
  int width = 0;                        // 0 = the camera's default still size
  int height = 0;
  std::filesystem::path rig_calibration;  // RigCalibration JSON of the lens lattice; "" = none
};

// A V4L2 camera node (drivers/v4l2).
struct V4l2SourceSettings {
  std::string device = "/dev/video0";
  std::string pixel_format = "RGB888";  // px pixel format name; the driver converts or adjusts
  int width = 0;                        // 0 = native: the rig calibration's sensor size, else the largest offered
  int height = 0;
  std::filesystem::path rig_calibration;  // RigCalibration JSON of the lens lattice; "" = none
  int exposure = -1;                      // V4L2_CID_EXPOSURE_ABSOLUTE (100 us units, sets manual exposure); -1 = leave
  int gain = -1;                          // V4L2_CID_GAIN (device units); -1 = leave
};

// A still camera tethered over USB and driven by PTP (drivers/ptp): one press = `shots` captures.
struct PtpSourceSettings {
  std::string vendor_id;   // USB vendor id, 4 hex digits ("04a9"); "" = the first PTP camera found
  std::string product_id;  // USB product id, 4 hex digits; "" = any product of vendor_id
  int shots = 5;           // captures per frame set (hand-held light field), [2, 15]
  int timeout_ms = 10000;  // one shot: InitiateCapture until the camera reports the new object, (0, 600000]
};

struct SourceSettings {
  std::string kind = "sim";  // "sim", "replay", "libcamera", "v4l2" or "ptp"
  SimSourceSettings sim;
  ReplaySourceSettings replay;
  LibcameraSourceSettings libcamera;
  V4l2SourceSettings v4l2;
  PtpSourceSettings ptp;
  int timeout_ms = 10000;  // how long one capture may take before it fails, (0, 600000]
  // Injected camera failures around whichever source is configured (sim/faults; for tests and
  // demos of the daemon's recovery). JSON: source.faults, a list of fault objects; [] = none.
  std::vector<FaultSpec> faults;
};

// What the clip looks like (pipeline/direct, pipeline/clip).
struct ClipSettings {
  std::string move = "auto";    // camera move, see pipeline/direct/direct_options.h
  std::string effect = "auto";  // image effect (auto, none, dof_change, ...), see there too
  double duration_s = 3.0;      // clip length in seconds, (0, 60]
  double fps = 30.0;            // frames per second, (0, 240]
  // How the clip plays the move (pipeline/direct/clip_timing.h): "once" (then hold_s on the last
  // frame), "loop" (out and back, seamless when repeated) or "boomerang"; eased "smooth" or "linear".
  std::string style = "once";
  std::string ease = "smooth";
  double hold_s = 0;  // once: seconds the last frame is held, [0, 60]
  // The clip's frame (pipeline/direct/output_frame.h): "WxH", or "" for aspect ("16:9", "9:16",
  // "1:1", "4:5", or "source") at `height` pixels (0 = the capture's).
  std::string size;
  std::string aspect = "source";
  int height = 0;
  // "mp4" (H.264), "gif" or "webp" (looping animations), or "png" (a folder of frames,
  // clips/<id>/frame_00000.png ...); see pipeline/clip/README.md.
  std::string format = "mp4";
  int crf = 20;                     // x264 quality, [0, 51]; lower is better and larger (mp4)
  std::string preset = "veryfast";  // x264 preset, ultrafast .. veryslow (mp4)
  int loop_count = 0;               // times a gif or webp plays, [0, 65535]; 0 = forever
  int webp_quality = 80;            // lossy WebP quality, [0, 100]
  int num_threads = 0;              // pipeline threads, 0 = all cores
  // Hand-held photos (the USB camera's shots) are processed, and the clip made, at this longer
  // side at most; 0 = full size, else [64, 16384] (pipeline/run/image_set_scale.h).
  int max_photo_side_px = 1200;
  // Haar cascades for face detection (Debian's opencv-data); "" = no face detection, so the
  // taxonomy sees no subjects. A folder without them costs a warning, not the daemon.
  std::filesystem::path face_cascades = "/usr/share/opencv4/haarcascades";
};

// Which renderer draws the clips (pipeline/render/gl/render_backend.h).
struct RenderSettings {
  // "auto" (GL on a GPU, else the faster one on the machine: the CPU today), "cpu", "egl" or
  // "osmesa"; a GL back end that cannot start falls back to the CPU, the clip's JSON says why.
  std::string backend = "auto";
};

// The one-button trigger on a Linux input device (device/trigger/input_trigger.h).
struct TriggerSettings {
  std::filesystem::path input_device;  // evdev node, e.g. /dev/input/event0; "" = none
  std::string key = "KEY_CAMERA";      // key name (KEY_CAMERA, KEY_ENTER, BTN_0, ...) or code number
  int debounce_ms = 50;                // presses closer than this to the last one are bounce, [0, 10000]
  int retry_ms = 2000;                 // reopen interval while the device is missing, [10, 600000]
};

// The child process each job's pipeline runs in (device/worker): what it may use before it is
// killed, and how often it may crash on one capture before that job is failed.
struct WorkerSettings {
  // Resident memory at which the worker is killed; 0 = three quarters of the machine's memory, so
  // a runaway job is stopped before the kernel's OOM killer picks a process. Else [64, 1048576].
  int memory_limit_mb = 0;
  // One job's processing; a 24 MP photo takes about a minute on 2 cores. [10, 86400]
  int timeout_s = 900;
  // Worker crashes (a signal, or a limit above) on one job before it is failed; a daemon that is
  // itself stopped or killed never counts. [1, 100]
  int max_crashes = 3;
};

// The web app and its JSON API (device/http).
struct HttpSettings {
  // "HOST:PORT" to listen on; "" = no HTTP. Port 0 takes a free port (the log and status name it).
  // An address other than loopback makes every request from another host need the access token.
  std::string listen = "127.0.0.1:8080";
  // Who must present the access token: "remote" (requests not from loopback) or "always" (behind
  // a reverse proxy on the same machine every request comes from loopback).
  std::string token_required = "remote";
  int max_body_kb = 256;            // request bodies (a shot file is a few kB), [1, 65536]
  int max_requests_in_flight = 64;  // more at once get 503, [1, 4096]
  int requests_per_s = 50;          // per client address, with a burst of twice that; more get 429, [1, 100000]
  int max_event_streams = 8;        // open /api/events streams; more get 503, [1, 64]
};

struct DaemonConfig {
  StorageOptions storage;  // JSON: storage.root, storage.min_free_mb, storage.quota_mb
  std::filesystem::path control_socket = "/run/parallax/control.sock";  // JSON: control.socket; "" = no socket
  // JSON: control.group: a group name or gid whose members may use the socket too (mode 0660,
  // the socket's group set to it); "" = the daemon's user and root only (mode 0600).
  std::string control_group;
  // JSON: storage.group: a group name or gid given read access to the store (its folders 02750,
  // owned by that group, so captures and clips made there are too); "" = the daemon's own group.
  std::string storage_group;
  SourceSettings source;
  ClipSettings clip;
  RenderSettings render;  // JSON: render.backend
  TriggerSettings trigger;
  WorkerSettings worker;            // JSON: worker.memory_limit_mb, worker.timeout_s, worker.max_crashes
  HttpSettings http;                // JSON: http.listen, http.token_required, http.max_body_kb, ...
  std::string log_levels = "info";  // JSON: log.levels, e.g. "info" or "info,depth=debug"

  // Checks ranges and names; errors name the JSON field ("clip.fps: 0 is not in (0, 240]").
  Status Validate() const;
};

// The clip's frame the settings describe; errors name the field ("clip.aspect: ...").
StatusOr<OutputFrameOptions> ClipOutputFrame(const ClipSettings& clip);

// Parses a config object. Absent fields keep their defaults; unknown fields and wrong types are
// errors naming the field ("source.sim.camra: unknown field (known: scene, camera, ...)").
StatusOr<DaemonConfig> DaemonConfigFromJson(const nlohmann::json& j);
// The effective config, every field written (what --print-config shows).
nlohmann::json DaemonConfigToJson(const DaemonConfig& config);

// Reads and parses a config file; errors name the file.
StatusOr<DaemonConfig> LoadDaemonConfigFile(const std::filesystem::path& path);

struct ConfigSource {
  DaemonConfig config;
  std::string origin;  // "--config /etc/parallax.json", "$PARALLAX_CONFIG=/x.json", "built-in defaults"
};

// Applies the lookup order: `flag_path` if non-empty, else `env_value` (the value of
// $PARALLAX_CONFIG, nullptr or empty when unset), else the defaults.
StatusOr<ConfigSource> ResolveDaemonConfig(const std::string& flag_path, const char* env_value);

}  // namespace px::device
