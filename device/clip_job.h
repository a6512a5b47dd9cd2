// The one capture-to-clip job, shared by the daemon and the `parallax` command line: read a
// recording, run the pipeline, stream the frames into a clip (MP4, GIF, WebP or a folder of PNG
// frames; pipeline/clip) beside the destination, then put the clip in place atomically with its
// poster (clips/<id>.poster.jpg), a small looping preview (clips/<id>.preview.webp), the shot that
// reproduces it (clips/<id>.shot.json) and its camera path and report (clips/<id>.json) beside it. A failed or
// cancelled job leaves no clip behind.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <string>

#include "capture/recording.h"
#include "pipeline/clip/clip_writer.h"
#include "pipeline/run/pipeline.h"

namespace px::device {

struct ClipJobOptions {
  PipelineOptions pipeline;  // depth, camera path (move, duration_s, fps), render, threads
  clip::ClipOptions clip;    // format, crf, preset, loop; its fps is replaced by pipeline.direct.fps
  Status Validate() const;
};

struct ClipJobReport {
  std::filesystem::path recording_dir;
  std::filesystem::path clip_path;     // absolute
  std::filesystem::path report_path;   // absolute, the JSON beside the clip
  std::filesystem::path poster_path;   // absolute, <id>.poster.jpg: the move's far end, full size
  std::filesystem::path preview_path;  // absolute, <id>.preview.webp: looping, 10 fps, 320 px
  uint64_t preview_bytes = 0;
  std::string source_model;  // from the recording: "sim:sim-pop9", ...
  PipelineReport pipeline;   // views, warnings, per-stage timings (with "encode"), camera path
  int frames_written = 0;
  std::string format;  // "mp4", "gif", "webp" or "png"
  int width = 0;       // stored size (MP4: even)
  int height = 0;
  uint64_t clip_bytes = 0;
  double total_ms = 0;  // the recording in memory to the clip in place, wall clock
};

// What goes into the report file: the camera path (pipeline/direct CameraPathToJson), figures,
// warnings and timings.
nlohmann::json ClipJobReportToJson(const ClipJobReport& report);

// The rig calibration a recording is processed with (its own), or for a lattice frame without
// one, an empty one with the lattice its source describes set in `pipeline_options` (the lattice
// is then found blind). `source` names the recording in the log.
RigCalibration RigCalibrationFor(const Recording& recording,
                                 const std::filesystem::path& source,
                                 PipelineOptions* pipeline_options);

// `clip_path` is the file to write (a folder for png). Errors: the recording's read error (naming
// its file), FAILED_PRECONDITION when a lattice frame comes without a rig calibration, the
// pipeline's error, the encoder's, or RESOURCE_EXHAUSTED when the disk fills. CANCELLED when
// `progress` returned false.
StatusOr<ClipJobReport> RunClipJob(const std::filesystem::path& recording_dir,
                                   const std::filesystem::path& clip_path,
                                   const ClipJobOptions& options,
                                   const ProgressCallback& progress = {});
// The same for a recording already in memory (photos `parallax clip` imported itself); `source`
// names where it came from in the report.
StatusOr<ClipJobReport> RunClipJob(const Recording& recording,
                                   const std::filesystem::path& source,
                                   const std::filesystem::path& clip_path,
                                   const ClipJobOptions& options,
                                   const ProgressCallback& progress = {});

// Where a clip of `format` goes for a destination named without regard to format: `path` with
// its extension replaced by the format's (clips/000007.mp4 -> clips/000007.gif; png: the folder
// clips/000007).
std::filesystem::path ClipPathForFormat(const std::filesystem::path& path, clip::ClipFormat format);

}  // namespace px::device
