// A recording: one captured shot on disk, the project's raw-capture format (FORMAT.md beside
// this file). The daemon writes one before any processing; ReplaySource plays them back.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include "drivers/source/frame_source.h"
#include "pipeline/core/frame_set.h"

namespace px {

struct Recording {
  static constexpr int kFormatVersion = 1;

  SourceDescription source;  // camera model, kind, rig calibration if known
  FrameSet frames;           // decoded frames with their metadata and status
  std::string created_by;    // free text: "parallaxd 0.1.0", "parallax sim"
  std::string created_at;    // UTC ISO 8601 ("2025-03-01T12:00:00Z"); WriteRecording stamps now when empty
};

// Writes frames first, then manifest.json last (write to a temporary name, fsync, rename,
// fsync the folder), so a folder with a manifest is always complete. `dir` must not exist or be
// empty. RESOURCE_EXHAUSTED when the disk is full (nothing half-written is left behind as a
// valid recording).
// INVALID_ARGUMENT (nothing written) when the recording contradicts itself: frames.kind differs
// from source.kind, an ok frame's buffer does not fill its size, the rig does not fit the frames.
// Other failures name the path; on any failure the files written so far are removed again.
Status WriteRecording(const std::filesystem::path& dir, const Recording& recording);

// Called with each file's final path just before it is renamed into place, manifest.json last.
// A non-OK result aborts the write as an I/O error would. For tests (a crash at that point
// leaves the folder as it is then) and for progress reporting.
using BeforeCommitHook = std::function<Status(const std::filesystem::path& final_path)>;
Status WriteRecording(const std::filesystem::path& dir,
                      const Recording& recording,
                      const BeforeCommitHook& before_commit);

// Loads and validates everything: the manifest's fields and types, each frame file's existence,
// decoding and size. Errors name the file and the field:
//   "/r/manifest.json: frames[2].pixel_format: 'MJPG' is not one of RGB888, ..."
//   "/r/frame_0002.png: truncated or not a PNG (...) (manifest.json frames[2])"
// NOT_FOUND without a manifest, INVALID_ARGUMENT for a bad manifest, DATA_LOSS for a missing,
// damaged or mismatching frame file. Frames whose status is not ok are loaded as recorded.
StatusOr<Recording> ReadRecording(const std::filesystem::path& dir);

}  // namespace px
