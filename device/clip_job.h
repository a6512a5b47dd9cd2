// The one capture-to-clip job, shared by the daemon and the `parallax` command line: read a
// recording, run the pipeline, stream the frames into an MP4 beside the destination, then put
// the clip in place atomically with its camera path and report (clips/<id>.json) beside it.
// A failed or cancelled job leaves no clip file behind.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <string>

#include "pipeline/clip/mp4_writer.h"
#include "pipeline/run/pipeline.h"

namespace px::device {

struct ClipJobOptions {
  PipelineOptions pipeline;  // depth, camera path (move, duration_s, fps), render, threads
  clip::Mp4Options mp4;      // crf, preset; its fps is replaced by pipeline.direct.fps
  Status Validate() const;
};

struct ClipJobReport {
  std::filesystem::path recording_dir;
  std::filesystem::path clip_path;    // absolute
  std::filesystem::path report_path;  // absolute, the JSON beside the clip
  std::string source_model;           // from the recording: "sim:sim-pop9", ...
  PipelineReport pipeline;            // views, warnings, per-stage timings (with "encode"), camera path
  int frames_written = 0;
  int width = 0;  // encoded size (even)
  int height = 0;
  uint64_t clip_bytes = 0;
  double total_ms = 0;  // read to rename, wall clock
};

// What goes into the report file: the camera path (pipeline/direct CameraPathToJson), figures,
// warnings and timings.
nlohmann::json ClipJobReportToJson(const ClipJobReport& report);

// Errors: the recording's read error (naming its file), FAILED_PRECONDITION when a lattice frame
// comes without a rig calibration, the pipeline's error, the encoder's, or RESOURCE_EXHAUSTED
// when the disk fills. CANCELLED when `progress` returned false.
StatusOr<ClipJobReport> RunClipJob(const std::filesystem::path& recording_dir,
                                   const std::filesystem::path& clip_path,
                                   const ClipJobOptions& options,
                                   const ProgressCallback& progress = {});

}  // namespace px::device
