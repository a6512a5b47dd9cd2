#include "capture/recording_manifest.h"

#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <utility>

#include "capture/frame_file.h"
#include "capture/recording.h"
#include "pipeline/core/json_fields.h"
#include "pipeline/core/rig_calibration_json.h"

namespace px::capture {
namespace {

using Json = nlohmann::json;
using json::FieldPath;
using json::IndexPath;

// Larger than any sensor we know (about 50 MP at 8192 px), small enough that width * height *
// 3 cannot overflow and a garbled manifest cannot ask for absurd buffers.
constexpr int64_t kMaxSidePx = 1 << 15;

Status Mistyped(const std::string& path, const std::string& want, const Json& got) {
  return InvalidArgumentError(path + ": want " + want + ", got " + std::string(got.type_name()));
}

StatusOr<uint64_t> GetUnsigned(const Json& object, const std::string& key, const std::string& parent) {
  PX_ASSIGN_OR_RETURN(const Json* value, json::GetField(object, key, parent));
  if (value->is_number_unsigned()) return value->get<uint64_t>();
  if (value->is_number_integer()) {
    return InvalidArgumentError(FieldPath(parent, key) + ": " + value->dump() + " is negative");
  }
  return Mistyped(FieldPath(parent, key), "a non-negative integer", *value);
}

StatusOr<int64_t> GetSigned(const Json& object, const std::string& key, const std::string& parent) {
  PX_ASSIGN_OR_RETURN(const Json* value, json::GetField(object, key, parent));
  if (value->is_number_unsigned() && value->get<uint64_t>() > uint64_t{std::numeric_limits<int64_t>::max()}) {
    return InvalidArgumentError(FieldPath(parent, key) + ": " + value->dump() + " does not fit in 64 signed bits");
  }
  if (!value->is_number_integer()) return Mistyped(FieldPath(parent, key), "an integer", *value);
  return value->get<int64_t>();
}

StatusOr<int> GetSide(const Json& object, const std::string& key, const std::string& parent) {
  PX_ASSIGN_OR_RETURN(int64_t value, json::GetInteger(object, key, parent));
  if (value < 0 || value > kMaxSidePx) {
    return InvalidArgumentError(FieldPath(parent, key) + ": " + std::to_string(value) + " is not in [0, " +
                                std::to_string(kMaxSidePx) + "] pixels");
  }
  return static_cast<int>(value);
}

// A string, or null (absent) for the optional file and checksum of a frame.
StatusOr<std::optional<std::string>> GetStringOrNull(const Json& object,
                                                     const std::string& key,
                                                     const std::string& parent) {
  PX_ASSIGN_OR_RETURN(const Json* value, json::GetField(object, key, parent));
  if (value->is_null()) return std::optional<std::string>();
  if (!value->is_string()) return Mistyped(FieldPath(parent, key), "a string or null", *value);
  return std::optional<std::string>(value->get<std::string>());
}

std::string AllPixelFormatNames() {
  std::string names;
  for (PixelFormat f : {PixelFormat::kRgb888,
                        PixelFormat::kBgr888,
                        PixelFormat::kGray8,
                        PixelFormat::kYuyv,
                        PixelFormat::kNv12,
                        PixelFormat::kBayerRggb8}) {
    names += (names.empty() ? "" : ", ") + std::string(PixelFormatName(f));
  }
  return names;
}

bool IsPlainFileName(const std::string& name) {
  if (name.empty() || name == "." || name == ".." || name.front() == '.' || name.size() > 255) return false;
  for (char c : name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) return false;
  }
  return true;
}

bool IsSha256Hex(const std::string& text) {
  if (text.size() != 64) return false;
  for (char c : text) {
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

StatusOr<FrameEntry> FrameEntryFromJson(const Json& j, const std::string& path) {
  FrameEntry entry;
  if (!j.is_object()) return Mistyped(path, "an object", j);
  PX_ASSIGN_OR_RETURN(entry.file, GetStringOrNull(j, "file", path));
  PX_ASSIGN_OR_RETURN(entry.width, GetSide(j, "width", path));
  PX_ASSIGN_OR_RETURN(entry.height, GetSide(j, "height", path));
  PX_ASSIGN_OR_RETURN(std::string format_name, json::GetString(j, "pixel_format", path));
  const std::optional<PixelFormat> format = ParsePixelFormat(format_name);
  if (!format) {
    return InvalidArgumentError(FieldPath(path, "pixel_format") + ": '" + format_name + "' is not one of " +
                                AllPixelFormatNames());
  }
  entry.pixel_format = *format;
  PX_ASSIGN_OR_RETURN(entry.sequence, GetUnsigned(j, "sequence", path));
  PX_ASSIGN_OR_RETURN(entry.timestamp_ns, GetSigned(j, "timestamp_ns", path));
  PX_ASSIGN_OR_RETURN(std::string status_name, json::GetString(j, "status", path));
  StatusOr<FrameStatus> status = ParseFrameStatus(status_name);
  if (!status.ok()) return status.status().WithContext(FieldPath(path, "status"));
  entry.status = *status;
  PX_ASSIGN_OR_RETURN(entry.status_detail, json::GetStringOr(j, "status_detail", path, ""));
  // Optional (recordings before it have none: unknown).
  PX_ASSIGN_OR_RETURN(entry.focal_length_px, json::GetNumberOr(j, "focal_length_px", path, 0.0));
  PX_ASSIGN_OR_RETURN(entry.focal_length_source, json::GetStringOr(j, "focal_length_source", path, ""));
  PX_ASSIGN_OR_RETURN(entry.bytes, GetUnsigned(j, "bytes", path));
  PX_ASSIGN_OR_RETURN(entry.sha256, GetStringOrNull(j, "sha256", path));
  return entry;
}

nlohmann::ordered_json FrameEntryToJson(const FrameEntry& entry) {
  nlohmann::ordered_json j;
  j["file"] = entry.file ? nlohmann::ordered_json(*entry.file) : nlohmann::ordered_json(nullptr);
  j["width"] = entry.width;
  j["height"] = entry.height;
  j["pixel_format"] = std::string(PixelFormatName(entry.pixel_format));
  j["sequence"] = entry.sequence;
  j["timestamp_ns"] = entry.timestamp_ns;
  j["status"] = std::string(FrameStatusName(entry.status));
  j["status_detail"] = entry.status_detail;
  if (entry.focal_length_px > 0) {  // written only when known: absent means unknown
    j["focal_length_px"] = entry.focal_length_px;
    j["focal_length_source"] = entry.focal_length_source;
  }
  j["bytes"] = entry.bytes;
  j["sha256"] = entry.sha256 ? nlohmann::ordered_json(*entry.sha256) : nlohmann::ordered_json(nullptr);
  return j;
}

Status ValidateFrameEntry(const FrameEntry& entry, const std::string& path) {
  for (const auto& [key, side] : {std::pair<const char*, int>{"width", entry.width}, {"height", entry.height}}) {
    if (side < 0 || side > kMaxSidePx) {
      return InvalidArgumentError(FieldPath(path, key) + ": " + std::to_string(side) + " is not in [0, " +
                                  std::to_string(kMaxSidePx) + "] pixels");
    }
  }
  if (!(std::isfinite(entry.focal_length_px) && entry.focal_length_px >= 0 && entry.focal_length_px <= 1e6)) {
    return InvalidArgumentError(FieldPath(path, "focal_length_px") + ": " + std::to_string(entry.focal_length_px) +
                                " is not in [0, 1e6] pixels");
  }
  if (entry.file.has_value() != entry.sha256.has_value()) {
    return InvalidArgumentError(FieldPath(path, entry.file ? "sha256" : "file") +
                                ": a frame has both a file and its sha256, or neither");
  }
  if (entry.sha256 && !IsSha256Hex(*entry.sha256)) {
    return InvalidArgumentError(FieldPath(path, "sha256") + ": '" + *entry.sha256 + "' is not 64 lowercase hex digits");
  }
  if (!entry.file) {
    if (entry.status == FrameStatus::kOk) {
      return InvalidArgumentError(FieldPath(path, "file") + ": null, but status ok promises a frame file");
    }
    if (entry.bytes != 0) {
      return InvalidArgumentError(FieldPath(path, "bytes") + ": " + std::to_string(entry.bytes) +
                                  " for a frame without a file, want 0");
    }
    return OkStatus();
  }
  if (!IsPlainFileName(*entry.file) || *entry.file == kManifestFileName) {
    return InvalidArgumentError(FieldPath(path, "file") + ": '" + *entry.file +
                                "' is not a plain file name in the recording folder");
  }
  StatusOr<FrameFileType> type = FrameFileTypeOf(*entry.file);
  if (!type.ok()) return type.status().WithContext(FieldPath(path, "file"));
  if (*type == FrameFileType::kPng && !PngCanHold(entry.pixel_format)) {
    return InvalidArgumentError(FieldPath(path, "file") + ": '" + *entry.file + "' is a PNG, but " +
                                std::string(PixelFormatName(entry.pixel_format)) + " frames are stored as .raw");
  }
  if (*type == FrameFileType::kJpeg &&
      (entry.pixel_format != PixelFormat::kRgb888 || entry.status != FrameStatus::kOk)) {
    return InvalidArgumentError(FieldPath(path, "file") + ": '" + *entry.file +
                                "' is a JPEG, which only an ok RGB888 frame may be");
  }
  // Writers store complete RGB888/BGR888/GRAY8 frames as PNG (or their camera's JPEG); a raw file for an ok frame of
  // those formats would let a changed pixel_format (SRGGB8 -> GRAY8) pass unnoticed.
  if (*type == FrameFileType::kRaw && entry.status == FrameStatus::kOk && PngCanHold(entry.pixel_format)) {
    return InvalidArgumentError(FieldPath(path, "file") + ": '" + *entry.file + "' is raw, but ok " +
                                std::string(PixelFormatName(entry.pixel_format)) + " frames are stored as PNG");
  }
  if (entry.status == FrameStatus::kOk || *type != FrameFileType::kRaw) {
    StatusOr<size_t> packed = PackedImageBytes(entry.pixel_format, entry.width, entry.height);
    if (!packed.ok()) return packed.status().WithContext(FieldPath(path, "width") + ", height");
    // A raw file holds the packed bytes themselves; only a frame marked bad may be short or long.
    if (entry.status == FrameStatus::kOk && *type == FrameFileType::kRaw && entry.bytes != *packed) {
      return InvalidArgumentError(FieldPath(path, "bytes") + ": " + std::to_string(entry.bytes) + ", but a " +
                                  std::to_string(entry.width) + "x" + std::to_string(entry.height) + " " +
                                  std::string(PixelFormatName(entry.pixel_format)) + " frame has " +
                                  std::to_string(*packed) + " bytes");
    }
  }
  return OkStatus();
}

// The rig calibration must describe the frames it comes with.
Status ValidateRigAgainstFrames(const Manifest& manifest) {
  if (!manifest.source.rig) return OkStatus();
  const RigCalibration& rig = *manifest.source.rig;
  const std::string rig_path = "source.rig_calibration";
  if (manifest.source.kind == FrameSetKind::kLatticeFrame) {
    if (rig.lattice.rows <= 0) return OkStatus();
    for (size_t i = 0; i < manifest.frames.size(); ++i) {
      const FrameEntry& frame = manifest.frames[i];
      if (frame.status != FrameStatus::kOk) continue;
      if (frame.width != rig.lattice.sensor_width || frame.height != rig.lattice.sensor_height) {
        return InvalidArgumentError(
            FieldPath(IndexPath("frames", i), "width") + ", height: " + std::to_string(frame.width) + "x" +
            std::to_string(frame.height) + " differs from the lattice's sensor size " +
            std::to_string(rig.lattice.sensor_width) + "x" + std::to_string(rig.lattice.sensor_height) + " (" +
            rig_path + ".lattice.sensor_width, sensor_height)");
      }
    }
    return OkStatus();
  }
  if (rig.lattice.rows > 0) {
    return InvalidArgumentError(rig_path + ".lattice: an image_set has no lattice");
  }
  if (rig.lenses.size() != manifest.frames.size()) {
    return InvalidArgumentError(rig_path + ".lenses: " + std::to_string(rig.lenses.size()) +
                                " lenses for an image_set of " + std::to_string(manifest.frames.size()) +
                                " frames, want one per frame");
  }
  for (size_t i = 0; i < manifest.frames.size(); ++i) {
    const FrameEntry& frame = manifest.frames[i];
    const CameraModel& camera = rig.lenses[i].camera;
    if (frame.status == FrameStatus::kOk && (frame.width != camera.width || frame.height != camera.height)) {
      return InvalidArgumentError(FieldPath(IndexPath("frames", i), "width") +
                                  ", height: " + std::to_string(frame.width) + "x" + std::to_string(frame.height) +
                                  " differs from " + IndexPath(rig_path + ".lenses", i) + ".camera's " +
                                  std::to_string(camera.width) + "x" + std::to_string(camera.height));
    }
  }
  return OkStatus();
}

int TwoDigits(std::string_view text, size_t at) { return (text[at] - '0') * 10 + (text[at + 1] - '0'); }

}  // namespace

std::string FrameFileName(size_t index, std::string_view extension) {
  char name[32];
  std::snprintf(name, sizeof(name), "frame_%04zu", index);
  return std::string(name) + std::string(extension);
}

std::string UtcNowIso8601() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

bool IsUtcIso8601(std::string_view text) {
  // YYYY-MM-DDTHH:MM:SS then an optional .fraction, then Z.
  constexpr std::string_view kShape = "dddd-dd-ddTdd:dd:dd";
  if (text.size() < kShape.size() + 1 || text.back() != 'Z') return false;
  for (size_t i = 0; i < kShape.size(); ++i) {
    const bool digit = std::isdigit(static_cast<unsigned char>(text[i])) != 0;
    if (kShape[i] == 'd' ? !digit : text[i] != kShape[i]) return false;
  }
  std::string_view fraction = text.substr(kShape.size(), text.size() - kShape.size() - 1);
  if (!fraction.empty()) {
    if (fraction.size() < 2 || fraction[0] != '.') return false;
    for (char c : fraction.substr(1)) {
      if (!std::isdigit(static_cast<unsigned char>(c))) return false;
    }
  }
  const int month = TwoDigits(text, 5), day = TwoDigits(text, 8);
  const int hour = TwoDigits(text, 11), minute = TwoDigits(text, 14), second = TwoDigits(text, 17);
  return month >= 1 && month <= 12 && day >= 1 && day <= 31 && hour <= 23 && minute <= 59 && second <= 60;
}

std::string ManifestToJsonText(const Manifest& manifest) {
  nlohmann::ordered_json j;
  j["format"] = std::string(kRecordingFormatName);
  j["format_version"] = Recording::kFormatVersion;
  j["created_by"] = manifest.created_by;
  j["created_at"] = manifest.created_at;
  nlohmann::ordered_json source;
  source["model"] = manifest.source.model;
  source["kind"] = std::string(FrameSetKindName(manifest.source.kind));
  if (manifest.source.rig) {
    // Through text so the calibration's own field order is kept; doubles print exactly.
    source["rig_calibration"] = nlohmann::ordered_json::parse(
        RigCalibrationToJson(*manifest.source.rig).dump(-1, ' ', false, Json::error_handler_t::replace));
  }
  if (manifest.source.lattice) {
    const LatticeHint& hint = *manifest.source.lattice;
    source["lattice"] = {{"rows", hint.rows},
                         {"cols", hint.cols},
                         {"tile_orientation", std::string(TileOrientationName(hint.orientation))}};
  }
  j["source"] = source;
  j["capture_id"] = manifest.capture_id;
  nlohmann::ordered_json frames = nlohmann::ordered_json::array();
  for (const FrameEntry& entry : manifest.frames) frames.push_back(FrameEntryToJson(entry));
  j["frames"] = frames;
  // Invalid UTF-8 in free text (a driver's status_detail) becomes U+FFFD instead of throwing.
  return j.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
}

StatusOr<Manifest> ManifestFromJson(const Json& j) {
  Manifest manifest;
  if (!j.is_object()) return Mistyped("document", "an object", j);
  PX_ASSIGN_OR_RETURN(std::string format, json::GetString(j, "format", ""));
  if (format != kRecordingFormatName) {
    return InvalidArgumentError("format: '" + format + "' is not " + std::string(kRecordingFormatName));
  }
  PX_ASSIGN_OR_RETURN(int64_t version, json::GetInteger(j, "format_version", ""));
  if (version != Recording::kFormatVersion) {
    return InvalidArgumentError("format_version: " + std::to_string(version) +
                                " is not a supported version (this build reads " +
                                std::to_string(Recording::kFormatVersion) + ")");
  }
  PX_ASSIGN_OR_RETURN(manifest.created_by, json::GetString(j, "created_by", ""));
  PX_ASSIGN_OR_RETURN(manifest.created_at, json::GetString(j, "created_at", ""));
  if (!IsUtcIso8601(manifest.created_at)) {
    return InvalidArgumentError("created_at: '" + manifest.created_at + "' is not UTC ISO 8601 (YYYY-MM-DDTHH:MM:SSZ)");
  }

  PX_ASSIGN_OR_RETURN(const Json* source, json::GetField(j, "source", ""));
  if (!source->is_object()) return Mistyped("source", "an object", *source);
  PX_ASSIGN_OR_RETURN(manifest.source.model, json::GetString(*source, "model", "source"));
  PX_ASSIGN_OR_RETURN(std::string kind, json::GetString(*source, "kind", "source"));
  StatusOr<FrameSetKind> parsed_kind = ParseFrameSetKind(kind);
  if (!parsed_kind.ok()) return parsed_kind.status().WithContext("source.kind");
  manifest.source.kind = *parsed_kind;
  if (source->contains("rig_calibration") && !(*source)["rig_calibration"].is_null()) {
    StatusOr<RigCalibration> rig = RigCalibrationFromJson((*source)["rig_calibration"], "source.rig_calibration");
    // RigCalibration::Validate's own messages do not carry the JSON path: add it once.
    if (!rig.ok()) {
      const Status error = rig.status();
      return error.message().rfind("source.rig_calibration", 0) == 0 ? error
                                                                     : error.WithContext("source.rig_calibration");
    }
    manifest.source.rig = *std::move(rig);
  }
  if (source->contains("lattice") && !(*source)["lattice"].is_null()) {
    const Json& lattice = (*source)["lattice"];
    if (!lattice.is_object()) return Mistyped("source.lattice", "an object", lattice);
    LatticeHint hint;
    PX_ASSIGN_OR_RETURN(const int64_t rows, json::GetIntegerOr(lattice, "rows", "source.lattice", 0));
    PX_ASSIGN_OR_RETURN(const int64_t cols, json::GetIntegerOr(lattice, "cols", "source.lattice", 0));
    if (rows < 0 || rows > 16 || cols < 0 || cols > 16) {
      return InvalidArgumentError("source.lattice: rows and cols must lie in [0, 16] (0: found blind), got " +
                                  std::to_string(rows) + "x" + std::to_string(cols));
    }
    hint.rows = static_cast<int>(rows);
    hint.cols = static_cast<int>(cols);
    PX_ASSIGN_OR_RETURN(const std::string orientation,
                        json::GetStringOr(lattice, "tile_orientation", "source.lattice", "upright"));
    StatusOr<TileOrientation> parsed = ParseTileOrientation(orientation);
    if (!parsed.ok()) return parsed.status().WithContext("source.lattice.tile_orientation");
    hint.orientation = *parsed;
    manifest.source.lattice = hint;
  }

  PX_ASSIGN_OR_RETURN(manifest.capture_id, GetUnsigned(j, "capture_id", ""));
  PX_ASSIGN_OR_RETURN(const Json* frames, json::GetField(j, "frames", ""));
  if (!frames->is_array()) return Mistyped("frames", "an array", *frames);
  for (size_t i = 0; i < frames->size(); ++i) {
    PX_ASSIGN_OR_RETURN(FrameEntry entry, FrameEntryFromJson((*frames)[i], IndexPath("frames", i)));
    manifest.frames.push_back(std::move(entry));
  }
  PX_RETURN_IF_ERROR(ValidateManifest(manifest));
  return manifest;
}

Status ValidateManifest(const Manifest& manifest) {
  if (manifest.frames.empty()) return InvalidArgumentError("frames: empty, a recording holds at least one frame");
  std::set<std::string> names;
  for (size_t i = 0; i < manifest.frames.size(); ++i) {
    const FrameEntry& entry = manifest.frames[i];
    const std::string path = IndexPath("frames", i);
    PX_RETURN_IF_ERROR(ValidateFrameEntry(entry, path));
    if (entry.file && !names.insert(*entry.file).second) {
      return InvalidArgumentError(FieldPath(path, "file") + ": '" + *entry.file + "' is used by an earlier frame");
    }
  }
  if (manifest.source.rig) {
    PX_RETURN_IF_ERROR(manifest.source.rig->Validate().WithContext("source.rig_calibration"));
  }
  return ValidateRigAgainstFrames(manifest);
}

}  // namespace px::capture
