// manifest.json of a recording (FORMAT.md): its fields as values, the JSON both ways, and the
// rules that tie the fields together. Errors name the field's JSON path ("frames[2].width: ...");
// the caller adds the file name. Files themselves are read and checked in recording.cc.
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/source/frame_source.h"
#include "pipeline/core/frame_set.h"

namespace px::capture {

inline constexpr std::string_view kManifestFileName = "manifest.json";
inline constexpr std::string_view kRecordingFormatName = "parallax.recording";

struct FrameEntry {
  std::optional<std::string> file;  // file name inside the folder; none when no bytes were captured
  PixelFormat pixel_format = PixelFormat::kBgr888;
  int width = 0;  // pixels
  int height = 0;
  uint64_t sequence = 0;
  int64_t timestamp_ns = 0;
  FrameStatus status = FrameStatus::kOk;
  std::string status_detail;
  double focal_length_px = 0;  // from the image's metadata (Frame::focal_length_px); 0 = unknown
  std::string focal_length_source;
  uint64_t bytes = 0;                 // size of `file` in bytes (0 without a file)
  std::optional<std::string> sha256;  // lowercase hex of the file's SHA-256; set iff `file` is
};

struct Manifest {
  std::string created_by;
  std::string created_at;  // UTC ISO 8601, "2025-03-01T12:00:00Z"
  SourceDescription source;
  uint64_t capture_id = 0;
  std::vector<FrameEntry> frames;
};

// "frame_0003.png": the name a writer gives frame `index`.
std::string FrameFileName(size_t index, std::string_view extension);

// The current time as UTC ISO 8601 with seconds ("2025-03-01T12:00:00Z").
std::string UtcNowIso8601();
// True for "YYYY-MM-DDTHH:MM:SS[.fraction]Z" with plausible field ranges.
bool IsUtcIso8601(std::string_view text);

std::string ManifestToJsonText(const Manifest& manifest);  // pretty-printed, fields in FORMAT.md order

// Parses the fields and their types (format name and version first), then ValidateManifest.
StatusOr<Manifest> ManifestFromJson(const nlohmann::json& j);

// The rules across fields: at least one frame; each file name plain, unique and .png/.raw; a
// file iff a checksum; no file only for a frame whose status is not ok; an ok frame has a
// size its pixel format allows and a file; PNG only for RGB888/BGR888/GRAY8; a lattice frame's ok
// frames match the rig's sensor size; an image set's rig (if any) has one lens per frame, of
// each ok frame's size, and no lattice.
Status ValidateManifest(const Manifest& manifest);

}  // namespace px::capture
