#include "device/config.h"

#include <algorithm>
#include <cctype>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "device/trigger/key_codes.h"
#include "pipeline/clip/clip_writer.h"
#include "pipeline/core/json_fields.h"
#include "pipeline/core/pixel_format.h"
#include "pipeline/direct/clip_timing.h"
#include "pipeline/direct/direct_options.h"
#include "pipeline/direct/taxonomy.h"
#include "pipeline/io/durable_file.h"
#include "pipeline/render/gl/render_backend.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;

constexpr double kBytesPerMb = 1000.0 * 1000.0;

// Reads the fields of one JSON object, remembering which keys it was asked for, so that the
// leftovers can be reported as unknown (a typo must not silently fall back to a default).
class ObjectReader {
 public:
  ObjectReader(const nlohmann::json& object, std::string path) : object_(object), path_(std::move(path)) {}

  Status CheckIsObject() const {
    if (!object_.is_object()) {
      return InvalidArgumentError((path_.empty() ? "config" : path_) + ": want an object, got " + object_.type_name());
    }
    return OkStatus();
  }

  // A nested object; absent means an empty one (all defaults).
  StatusOr<ObjectReader> Child(const std::string& key) {
    known_.push_back(key);
    static const nlohmann::json kEmpty = nlohmann::json::object();
    const std::string child_path = json::FieldPath(path_, key);
    auto it = object_.find(key);
    ObjectReader child(it == object_.end() ? kEmpty : *it, child_path);
    PX_RETURN_IF_ERROR(child.CheckIsObject());
    return child;
  }

  Status String(const std::string& key, std::string* value) {
    known_.push_back(key);
    PX_ASSIGN_OR_RETURN(*value, json::GetStringOr(object_, key, path_, *value));
    return OkStatus();
  }
  Status Path(const std::string& key, fs::path* value) {
    std::string text = value->string();
    PX_RETURN_IF_ERROR(String(key, &text));
    *value = text;
    return OkStatus();
  }
  Status Number(const std::string& key, double* value) {
    known_.push_back(key);
    PX_ASSIGN_OR_RETURN(*value, json::GetNumberOr(object_, key, path_, *value));
    return OkStatus();
  }
  Status Int(const std::string& key, int* value) {
    known_.push_back(key);
    PX_ASSIGN_OR_RETURN(int64_t v, json::GetIntegerOr(object_, key, path_, *value));
    if (v < INT32_MIN || v > INT32_MAX) {
      return InvalidArgumentError(json::FieldPath(path_, key) + ": " + std::to_string(v) + " is out of range");
    }
    *value = static_cast<int>(v);
    return OkStatus();
  }
  Status Uint64(const std::string& key, uint64_t* value) {
    known_.push_back(key);
    PX_ASSIGN_OR_RETURN(int64_t v, json::GetIntegerOr(object_, key, path_, static_cast<int64_t>(*value)));
    if (v < 0) return InvalidArgumentError(json::FieldPath(path_, key) + ": " + std::to_string(v) + " is negative");
    *value = static_cast<uint64_t>(v);
    return OkStatus();
  }
  // An optional field parsed elsewhere (a list): nullptr when absent.
  const nlohmann::json* Raw(const std::string& key) {
    known_.push_back(key);
    auto it = object_.find(key);
    return it == object_.end() ? nullptr : &*it;
  }
  Status Bool(const std::string& key, bool* value) {
    known_.push_back(key);
    PX_ASSIGN_OR_RETURN(*value, json::GetBoolOr(object_, key, path_, *value));
    return OkStatus();
  }

  // Call after reading every field: names the first key nobody asked for.
  Status CheckNoUnknownFields() const {
    const std::set<std::string> known(known_.begin(), known_.end());
    for (const auto& [key, value] : object_.items()) {
      if (known.count(key)) continue;
      std::string list;
      for (const std::string& k : known_) list += (list.empty() ? "" : ", ") + k;
      return InvalidArgumentError(json::FieldPath(path_, key) + ": unknown field (known: " + list + ")");
    }
    return OkStatus();
  }

 private:
  const nlohmann::json& object_;
  std::string path_;
  std::vector<std::string> known_;
};

std::string FormatNumber(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

Status RangeError(const std::string& field, double value, const std::string& range) {
  return InvalidArgumentError(field + ": " + FormatNumber(value) + " is not in " + range);
}

// OK when lo <= value <= hi, else the RangeError naming [lo, hi].
Status CheckInRange(const std::string& field, int value, int lo, int hi) {
  if (value >= lo && value <= hi) return OkStatus();
  return RangeError(field, value, "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

Status ValidateLibcamera(const LibcameraSourceSettings& settings) {
  if (!ParsePixelFormat(settings.pixel_format)) {
    return InvalidArgumentError("source.libcamera.pixel_format: '" + settings.pixel_format +
                                "' is not one of RGB888, BGR888, GRAY8, YUYV, NV12, SRGGB8");
  }
  if (settings.width < 0 || settings.width > 16384) {
    return RangeError("source.libcamera.width", settings.width, "[0, 16384] (0 = the camera's)");
  }
  if (settings.height < 0 || settings.height > 16384) {
    return RangeError("source.libcamera.height", settings.height, "[0, 16384] (0 = the camera's)");
  }
  if ((settings.width == 0) != (settings.height == 0)) {
    return InvalidArgumentError("source.libcamera.width, height: give both or neither");
  }
  return OkStatus();
}

Status ValidateV4l2(const V4l2SourceSettings& settings) {
  if (settings.device.empty()) return InvalidArgumentError("source.v4l2.device: empty");
  if (!ParsePixelFormat(settings.pixel_format)) {
    return InvalidArgumentError("source.v4l2.pixel_format: '" + settings.pixel_format +
                                "' is not one of RGB888, BGR888, GRAY8, YUYV, NV12, SRGGB8");
  }
  if (settings.width < 0 || settings.width > 16384) {
    return RangeError("source.v4l2.width", settings.width, "[0, 16384] (0 = native)");
  }
  if (settings.height < 0 || settings.height > 16384) {
    return RangeError("source.v4l2.height", settings.height, "[0, 16384] (0 = native)");
  }
  if ((settings.width == 0) != (settings.height == 0)) {
    return InvalidArgumentError("source.v4l2.width, height: give both or neither");
  }
  if (settings.exposure < -1) return RangeError("source.v4l2.exposure", settings.exposure, "[-1, ...) (-1 = leave)");
  if (settings.gain < -1) return RangeError("source.v4l2.gain", settings.gain, "[-1, ...) (-1 = leave)");
  return OkStatus();
}

Status ValidatePtp(const PtpSourceSettings& settings) {
  auto is_usb_id = [](const std::string& id) {
    return id.size() == 4 && id.find_first_not_of("0123456789abcdefABCDEF") == std::string::npos;
  };
  if (!settings.vendor_id.empty() && !is_usb_id(settings.vendor_id)) {
    return InvalidArgumentError("source.ptp.vendor_id: '" + settings.vendor_id + "' is not 4 hex digits (e.g. 04a9)");
  }
  if (!settings.product_id.empty() && !is_usb_id(settings.product_id)) {
    return InvalidArgumentError("source.ptp.product_id: '" + settings.product_id + "' is not 4 hex digits (e.g. 3218)");
  }
  if (settings.vendor_id.empty() && !settings.product_id.empty()) {
    return InvalidArgumentError("source.ptp.product_id: given without source.ptp.vendor_id");
  }
  if (settings.shots < 2 || settings.shots > 15) return RangeError("source.ptp.shots", settings.shots, "[2, 15]");
  if (settings.timeout_ms <= 0 || settings.timeout_ms > 600000) {
    return RangeError("source.ptp.timeout_ms", settings.timeout_ms, "(0, 600000]");
  }
  return OkStatus();
}

Status ValidateHttp(const HttpSettings& http) {
  if (!http.listen.empty()) {
    const size_t colon = http.listen.rfind(':');
    const std::string port = colon == std::string::npos ? "" : http.listen.substr(colon + 1);
    if (colon == 0 || colon == std::string::npos || port.empty() || port.size() > 5 ||
        port.find_first_not_of("0123456789") != std::string::npos || std::stoi(port) > 65535) {
      return InvalidArgumentError("http.listen: '" + http.listen + "' is not HOST:PORT (e.g. 127.0.0.1:8080)");
    }
  }
  if (http.token_required != "remote" && http.token_required != "always") {
    return InvalidArgumentError("http.token_required: '" + http.token_required + "' is not one of remote, always");
  }
  PX_RETURN_IF_ERROR(CheckInRange("http.max_body_kb", http.max_body_kb, 1, 65536));
  PX_RETURN_IF_ERROR(CheckInRange("http.max_requests_in_flight", http.max_requests_in_flight, 1, 4096));
  PX_RETURN_IF_ERROR(CheckInRange("http.requests_per_s", http.requests_per_s, 1, 100000));
  PX_RETURN_IF_ERROR(CheckInRange("http.max_event_streams", http.max_event_streams, 1, 64));
  return OkStatus();
}

Status ValidateTrigger(const TriggerSettings& trigger) {
  if (auto key = ParseKeyCode(trigger.key); !key.ok()) return key.status().WithContext("trigger.key");
  PX_RETURN_IF_ERROR(CheckInRange("trigger.debounce_ms", trigger.debounce_ms, 0, 10000));
  PX_RETURN_IF_ERROR(CheckInRange("trigger.retry_ms", trigger.retry_ms, 10, 600000));
  return OkStatus();
}

Status ValidateWorker(const WorkerSettings& worker) {
  if (worker.memory_limit_mb != 0 && (worker.memory_limit_mb < 64 || worker.memory_limit_mb > 1048576)) {
    return RangeError("worker.memory_limit_mb", worker.memory_limit_mb, "0 or [64, 1048576]");
  }
  PX_RETURN_IF_ERROR(CheckInRange("worker.timeout_s", worker.timeout_s, 10, 86400));
  PX_RETURN_IF_ERROR(CheckInRange("worker.max_crashes", worker.max_crashes, 1, 100));
  return OkStatus();
}

}  // namespace

StatusOr<OutputFrameOptions> ClipOutputFrame(const ClipSettings& clip) {
  OutputFrameOptions frame;
  if (!clip.size.empty()) {
    PX_RETURN_IF_ERROR(ParseOutputSize(clip.size, &frame).WithContext("clip.size"));
    return frame;
  }
  PX_RETURN_IF_ERROR(ParseOutputAspect(clip.aspect, &frame).WithContext("clip.aspect"));
  frame.height = clip.height;
  PX_RETURN_IF_ERROR(frame.Validate().WithContext("clip.height"));
  return frame;
}

Status DaemonConfig::Validate() const {
  PX_RETURN_IF_ERROR(storage.Validate());
  if (control_socket.string().size() > 107) {
    return InvalidArgumentError("control.socket: '" + control_socket.string() + "' is longer than 107 bytes");
  }
  if (!control_group.empty()) {
    const bool numeric = std::all_of(
        control_group.begin(), control_group.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
    const bool name = control_group.size() <= 32 && control_group.front() != '-' &&
                      std::all_of(control_group.begin(), control_group.end(), [](char c) {
                        return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
                      });
    if (!(numeric ? control_group.size() <= 9 : name)) {
      return InvalidArgumentError("control.group: '" + control_group +
                                  "' is neither a group name (letters, digits, _ - ., at most 32) nor a gid");
    }
  }
  if (source.kind != "sim" && source.kind != "replay" && source.kind != "libcamera" && source.kind != "v4l2" &&
      source.kind != "ptp") {
    return InvalidArgumentError("source.kind: '" + source.kind + "' is not one of sim, replay, libcamera, v4l2, ptp");
  }
  if (source.sim.camera != "pop9" && source.sim.camera != "integral5x4") {
    return InvalidArgumentError("source.sim.camera: '" + source.sim.camera + "' is not one of pop9, integral5x4");
  }
  if (source.sim.tile_width < 0 || source.sim.tile_width > 8192) {
    return RangeError("source.sim.tile_width", source.sim.tile_width, "[0, 8192] (0 = the preset's)");
  }
  if (source.sim.tile_height < 0 || source.sim.tile_height > 8192) {
    return RangeError("source.sim.tile_height", source.sim.tile_height, "[0, 8192] (0 = the preset's)");
  }
  if (source.kind == "replay" && source.replay.path.empty()) {
    return InvalidArgumentError("source.replay.path: empty, but source.kind is replay");
  }
  PX_RETURN_IF_ERROR(ValidateLibcamera(source.libcamera));
  PX_RETURN_IF_ERROR(ValidateV4l2(source.v4l2));
  PX_RETURN_IF_ERROR(ValidatePtp(source.ptp));
  PX_RETURN_IF_ERROR(ValidateTrigger(trigger));
  PX_RETURN_IF_ERROR(ValidateWorker(worker));
  PX_RETURN_IF_ERROR(ValidateHttp(http));
  if (source.timeout_ms <= 0 || source.timeout_ms > 600000) {
    return RangeError("source.timeout_ms", source.timeout_ms, "(0, 600000]");
  }
  if (clip.move.empty()) return InvalidArgumentError("clip.move: empty");
  if (clip.effect != "auto" && !direct::ParseEffect(clip.effect).ok()) {
    return InvalidArgumentError("clip.effect: '" + clip.effect + "' is not one of " + KnownEffectsText());
  }
  if (!(clip.duration_s > 0 && clip.duration_s <= 60)) return RangeError("clip.duration_s", clip.duration_s, "(0, 60]");
  if (!(clip.fps > 0 && clip.fps <= 240)) return RangeError("clip.fps", clip.fps, "(0, 240]");
  if (auto style = ParseClipStyle(clip.style); !style.ok()) return style.status().WithContext("clip.style");
  if (auto ease = ParseClipEase(clip.ease); !ease.ok()) return ease.status().WithContext("clip.ease");
  if (!(clip.hold_s >= 0 && clip.hold_s <= 60)) return RangeError("clip.hold_s", clip.hold_s, "[0, 60]");
  if (StatusOr<OutputFrameOptions> frame = ClipOutputFrame(clip); !frame.ok()) return frame.status();
  if (clip.hold_s > 0 && clip.style != "once") {
    return InvalidArgumentError("clip.hold_s: only a clip played once holds its last frame (clip.style is " +
                                clip.style + ")");
  }
  if (clip.crf < 0 || clip.crf > 51) return RangeError("clip.crf", clip.crf, "[0, 51]");
  static const std::set<std::string> kPresets = {
      "ultrafast", "superfast", "veryfast", "faster", "fast", "medium", "slow", "slower", "veryslow"};
  if (!kPresets.count(clip.preset)) {
    return InvalidArgumentError("clip.preset: '" + clip.preset +
                                "' is not one of ultrafast, superfast, veryfast, faster, fast, medium, slow, "
                                "slower, veryslow");
  }
  if (Status format = clip::ParseClipFormat(clip.format).status(); !format.ok()) return format;
  if (clip.loop_count < 0 || clip.loop_count > 65535) {
    return RangeError("clip.loop_count", clip.loop_count, "[0, 65535] (0 = forever)");
  }
  if (clip.webp_quality < 0 || clip.webp_quality > 100) {
    return RangeError("clip.webp_quality", clip.webp_quality, "[0, 100]");
  }
  if (clip.num_threads < 0 || clip.num_threads > 256) {
    return RangeError("clip.num_threads", clip.num_threads, "[0, 256] (0 = all cores)");
  }
  if (clip.max_photo_side_px != 0 && (clip.max_photo_side_px < 64 || clip.max_photo_side_px > 16384)) {
    return RangeError("clip.max_photo_side_px", clip.max_photo_side_px, "0 (full size) or [64, 16384]");
  }
  if (!render::gl::ParseRenderBackend(render.backend).ok()) {
    return InvalidArgumentError("render.backend: '" + render.backend + "' is not one of auto, cpu, egl, osmesa");
  }
  if (log_levels.empty()) return InvalidArgumentError("log.levels: empty");
  return OkStatus();
}

StatusOr<DaemonConfig> DaemonConfigFromJson(const nlohmann::json& j) {
  DaemonConfig config;
  ObjectReader root(j, "");
  PX_RETURN_IF_ERROR(root.CheckIsObject());

  PX_ASSIGN_OR_RETURN(ObjectReader storage, root.Child("storage"));
  PX_RETURN_IF_ERROR(storage.Path("root", &config.storage.root));
  double min_free_mb = static_cast<double>(config.storage.min_free_bytes) / kBytesPerMb;
  PX_RETURN_IF_ERROR(storage.Number("min_free_mb", &min_free_mb));
  if (!(min_free_mb >= 0 && min_free_mb < 1e9)) return RangeError("storage.min_free_mb", min_free_mb, "[0, 1e9)");
  config.storage.min_free_bytes = static_cast<uint64_t>(min_free_mb * kBytesPerMb + 0.5);
  double quota_mb = static_cast<double>(config.storage.quota_bytes) / kBytesPerMb;
  PX_RETURN_IF_ERROR(storage.Number("quota_mb", &quota_mb));
  if (!(quota_mb >= 0 && quota_mb < 1e9)) return RangeError("storage.quota_mb", quota_mb, "[0, 1e9) (0 = no quota)");
  config.storage.quota_bytes = static_cast<uint64_t>(quota_mb * kBytesPerMb + 0.5);
  PX_RETURN_IF_ERROR(storage.String("group", &config.storage_group));
  PX_RETURN_IF_ERROR(storage.CheckNoUnknownFields());

  PX_ASSIGN_OR_RETURN(ObjectReader control, root.Child("control"));
  PX_RETURN_IF_ERROR(control.Path("socket", &config.control_socket));
  PX_RETURN_IF_ERROR(control.String("group", &config.control_group));
  PX_RETURN_IF_ERROR(control.CheckNoUnknownFields());

  PX_ASSIGN_OR_RETURN(ObjectReader source, root.Child("source"));
  PX_RETURN_IF_ERROR(source.String("kind", &config.source.kind));
  PX_RETURN_IF_ERROR(source.Int("timeout_ms", &config.source.timeout_ms));
  if (const nlohmann::json* faults = source.Raw("faults")) {
    PX_ASSIGN_OR_RETURN(config.source.faults, FaultSpecsFromJson(*faults, "source.faults"));
  }
  PX_ASSIGN_OR_RETURN(ObjectReader sim, source.Child("sim"));
  PX_RETURN_IF_ERROR(sim.Path("scene", &config.source.sim.scene));
  PX_RETURN_IF_ERROR(sim.String("camera", &config.source.sim.camera));
  PX_RETURN_IF_ERROR(sim.Int("tile_width", &config.source.sim.tile_width));
  PX_RETURN_IF_ERROR(sim.Int("tile_height", &config.source.sim.tile_height));
  PX_RETURN_IF_ERROR(sim.Uint64("seed", &config.source.sim.seed));
  PX_RETURN_IF_ERROR(sim.CheckNoUnknownFields());
  PX_ASSIGN_OR_RETURN(ObjectReader replay, source.Child("replay"));
  PX_RETURN_IF_ERROR(replay.Path("path", &config.source.replay.path));
  PX_RETURN_IF_ERROR(replay.Bool("loop", &config.source.replay.loop));
  PX_RETURN_IF_ERROR(replay.CheckNoUnknownFields());
  PX_ASSIGN_OR_RETURN(ObjectReader libcamera, source.Child("libcamera"));
  PX_RETURN_IF_ERROR(libcamera.String("camera", &config.source.libcamera.camera));
  PX_RETURN_IF_ERROR(libcamera.String("pixel_format", &config.source.libcamera.pixel_format));
  PX_RETURN_IF_ERROR(libcamera.Int("width", &config.source.libcamera.width));
  PX_RETURN_IF_ERROR(libcamera.Int("height", &config.source.libcamera.height));
  PX_RETURN_IF_ERROR(libcamera.Path("rig_calibration", &config.source.libcamera.rig_calibration));
  PX_RETURN_IF_ERROR(libcamera.CheckNoUnknownFields());
  PX_ASSIGN_OR_RETURN(ObjectReader v4l2, source.Child("v4l2"));
  PX_RETURN_IF_ERROR(v4l2.String("device", &config.source.v4l2.device));
  PX_RETURN_IF_ERROR(v4l2.String("pixel_format", &config.source.v4l2.pixel_format));
  PX_RETURN_IF_ERROR(v4l2.Int("width", &config.source.v4l2.width));
  PX_RETURN_IF_ERROR(v4l2.Int("height", &config.source.v4l2.height));
  PX_RETURN_IF_ERROR(v4l2.Path("rig_calibration", &config.source.v4l2.rig_calibration));
  PX_RETURN_IF_ERROR(v4l2.Int("exposure", &config.source.v4l2.exposure));
  PX_RETURN_IF_ERROR(v4l2.Int("gain", &config.source.v4l2.gain));
  PX_RETURN_IF_ERROR(v4l2.CheckNoUnknownFields());
  PX_ASSIGN_OR_RETURN(ObjectReader ptp, source.Child("ptp"));
  PX_RETURN_IF_ERROR(ptp.String("vendor_id", &config.source.ptp.vendor_id));
  PX_RETURN_IF_ERROR(ptp.String("product_id", &config.source.ptp.product_id));
  PX_RETURN_IF_ERROR(ptp.Int("shots", &config.source.ptp.shots));
  PX_RETURN_IF_ERROR(ptp.Int("timeout_ms", &config.source.ptp.timeout_ms));
  PX_RETURN_IF_ERROR(ptp.CheckNoUnknownFields());
  PX_RETURN_IF_ERROR(source.CheckNoUnknownFields());

  PX_ASSIGN_OR_RETURN(ObjectReader clip, root.Child("clip"));
  PX_RETURN_IF_ERROR(clip.String("move", &config.clip.move));
  PX_RETURN_IF_ERROR(clip.String("effect", &config.clip.effect));
  PX_RETURN_IF_ERROR(clip.Number("duration_s", &config.clip.duration_s));
  PX_RETURN_IF_ERROR(clip.String("style", &config.clip.style));
  PX_RETURN_IF_ERROR(clip.String("ease", &config.clip.ease));
  PX_RETURN_IF_ERROR(clip.Number("hold_s", &config.clip.hold_s));
  PX_RETURN_IF_ERROR(clip.String("size", &config.clip.size));
  PX_RETURN_IF_ERROR(clip.String("aspect", &config.clip.aspect));
  PX_RETURN_IF_ERROR(clip.Int("height", &config.clip.height));
  PX_RETURN_IF_ERROR(clip.Number("fps", &config.clip.fps));
  PX_RETURN_IF_ERROR(clip.String("format", &config.clip.format));
  PX_RETURN_IF_ERROR(clip.Int("crf", &config.clip.crf));
  PX_RETURN_IF_ERROR(clip.String("preset", &config.clip.preset));
  PX_RETURN_IF_ERROR(clip.Int("loop_count", &config.clip.loop_count));
  PX_RETURN_IF_ERROR(clip.Int("webp_quality", &config.clip.webp_quality));
  PX_RETURN_IF_ERROR(clip.Int("num_threads", &config.clip.num_threads));
  PX_RETURN_IF_ERROR(clip.Int("max_photo_side_px", &config.clip.max_photo_side_px));
  PX_RETURN_IF_ERROR(clip.Path("face_cascades", &config.clip.face_cascades));
  PX_RETURN_IF_ERROR(clip.CheckNoUnknownFields());

  PX_ASSIGN_OR_RETURN(ObjectReader render, root.Child("render"));
  PX_RETURN_IF_ERROR(render.String("backend", &config.render.backend));
  PX_RETURN_IF_ERROR(render.CheckNoUnknownFields());

  PX_ASSIGN_OR_RETURN(ObjectReader trigger, root.Child("trigger"));
  PX_RETURN_IF_ERROR(trigger.Path("input_device", &config.trigger.input_device));
  PX_RETURN_IF_ERROR(trigger.String("key", &config.trigger.key));
  PX_RETURN_IF_ERROR(trigger.Int("debounce_ms", &config.trigger.debounce_ms));
  PX_RETURN_IF_ERROR(trigger.Int("retry_ms", &config.trigger.retry_ms));
  PX_RETURN_IF_ERROR(trigger.CheckNoUnknownFields());

  PX_ASSIGN_OR_RETURN(ObjectReader worker, root.Child("worker"));
  PX_RETURN_IF_ERROR(worker.Int("memory_limit_mb", &config.worker.memory_limit_mb));
  PX_RETURN_IF_ERROR(worker.Int("timeout_s", &config.worker.timeout_s));
  PX_RETURN_IF_ERROR(worker.Int("max_crashes", &config.worker.max_crashes));
  PX_RETURN_IF_ERROR(worker.CheckNoUnknownFields());

  PX_ASSIGN_OR_RETURN(ObjectReader http, root.Child("http"));
  PX_RETURN_IF_ERROR(http.String("listen", &config.http.listen));
  PX_RETURN_IF_ERROR(http.String("token_required", &config.http.token_required));
  PX_RETURN_IF_ERROR(http.Int("max_body_kb", &config.http.max_body_kb));
  PX_RETURN_IF_ERROR(http.Int("max_requests_in_flight", &config.http.max_requests_in_flight));
  PX_RETURN_IF_ERROR(http.Int("requests_per_s", &config.http.requests_per_s));
  PX_RETURN_IF_ERROR(http.Int("max_event_streams", &config.http.max_event_streams));
  PX_RETURN_IF_ERROR(http.CheckNoUnknownFields());

  PX_ASSIGN_OR_RETURN(ObjectReader log, root.Child("log"));
  PX_RETURN_IF_ERROR(log.String("levels", &config.log_levels));
  PX_RETURN_IF_ERROR(log.CheckNoUnknownFields());

  PX_RETURN_IF_ERROR(root.CheckNoUnknownFields());
  PX_RETURN_IF_ERROR(config.Validate());
  return config;
}

nlohmann::json DaemonConfigToJson(const DaemonConfig& config) {
  nlohmann::json j;
  j["storage"] = {{"root", config.storage.root.string()},
                  {"min_free_mb", static_cast<double>(config.storage.min_free_bytes) / kBytesPerMb},
                  {"quota_mb", static_cast<double>(config.storage.quota_bytes) / kBytesPerMb},
                  {"group", config.storage_group}};
  j["control"] = {{"socket", config.control_socket.string()}, {"group", config.control_group}};
  j["source"] = {
      {"kind", config.source.kind},
      {"timeout_ms", config.source.timeout_ms},
      {"faults", FaultSpecsToJson(config.source.faults)},
      {"sim",
       {{"scene", config.source.sim.scene.string()},
        {"camera", config.source.sim.camera},
        {"tile_width", config.source.sim.tile_width},
        {"tile_height", config.source.sim.tile_height},
        {"seed", config.source.sim.seed}}},
      {"replay", {{"path", config.source.replay.path.string()}, {"loop", config.source.replay.loop}}},
      {"libcamera",
       {{"camera", config.source.libcamera.camera},
        {"pixel_format", config.source.libcamera.pixel_format},
        {"width", config.source.libcamera.width},
        {"height", config.source.libcamera.height},
        {"rig_calibration", config.source.libcamera.rig_calibration.string()}}},
      {"v4l2",
       {{"device", config.source.v4l2.device},
        {"pixel_format", config.source.v4l2.pixel_format},
        {"width", config.source.v4l2.width},
        {"height", config.source.v4l2.height},
        {"rig_calibration", config.source.v4l2.rig_calibration.string()},
        {"exposure", config.source.v4l2.exposure},
        {"gain", config.source.v4l2.gain}}},
      {"ptp",
       {{"vendor_id", config.source.ptp.vendor_id},
        {"product_id", config.source.ptp.product_id},
        {"shots", config.source.ptp.shots},
        {"timeout_ms", config.source.ptp.timeout_ms}}},
  };
  j["clip"] = {{"move", config.clip.move},
               {"effect", config.clip.effect},
               {"duration_s", config.clip.duration_s},
               {"style", config.clip.style},
               {"ease", config.clip.ease},
               {"hold_s", config.clip.hold_s},
               {"size", config.clip.size},
               {"aspect", config.clip.aspect},
               {"height", config.clip.height},
               {"fps", config.clip.fps},
               {"format", config.clip.format},
               {"crf", config.clip.crf},
               {"preset", config.clip.preset},
               {"loop_count", config.clip.loop_count},
               {"webp_quality", config.clip.webp_quality},
               {"num_threads", config.clip.num_threads},
               {"max_photo_side_px", config.clip.max_photo_side_px},
               {"face_cascades", config.clip.face_cascades.string()}};
  j["render"] = {{"backend", config.render.backend}};
  j["trigger"] = {{"input_device", config.trigger.input_device.string()},
                  {"key", config.trigger.key},
                  {"debounce_ms", config.trigger.debounce_ms},
                  {"retry_ms", config.trigger.retry_ms}};
  j["worker"] = {{"memory_limit_mb", config.worker.memory_limit_mb},
                 {"timeout_s", config.worker.timeout_s},
                 {"max_crashes", config.worker.max_crashes}};
  j["http"] = {{"listen", config.http.listen},
               {"token_required", config.http.token_required},
               {"max_body_kb", config.http.max_body_kb},
               {"max_requests_in_flight", config.http.max_requests_in_flight},
               {"requests_per_s", config.http.requests_per_s},
               {"max_event_streams", config.http.max_event_streams}};
  j["log"] = {{"levels", config.log_levels}};
  return j;
}

StatusOr<DaemonConfig> LoadDaemonConfigFile(const fs::path& path) {
  auto text = ReadFileToString(path);
  if (!text.ok()) return text.status().WithContext("config");
  PX_ASSIGN_OR_RETURN(nlohmann::json j, json::Parse(*text, path.string()));
  auto config = DaemonConfigFromJson(j);
  if (!config.ok()) return config.status().WithContext(path.string());
  return config;
}

StatusOr<ConfigSource> ResolveDaemonConfig(const std::string& flag_path, const char* env_value) {
  ConfigSource source;
  if (!flag_path.empty()) {
    PX_ASSIGN_OR_RETURN(source.config, LoadDaemonConfigFile(flag_path));
    source.origin = "--config " + flag_path;
  } else if (env_value != nullptr && *env_value != '\0') {
    auto config = LoadDaemonConfigFile(env_value);
    if (!config.ok()) return config.status().WithContext("$PARALLAX_CONFIG");
    source.config = std::move(config).value();
    source.origin = std::string("$PARALLAX_CONFIG=") + env_value;
  } else {
    source.origin = "built-in defaults";
  }
  return source;
}

}  // namespace px::device
