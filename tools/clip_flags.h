// The flags that say how a clip is made (move, size, style, format, quality, ...), shared by
// `parallax clip` and the commands that make many clips (`batch`, `rerender`), so every one of
// them takes the same flags with the same defaults and checks.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "device/clip_job.h"
#include "pipeline/core/status.h"

namespace px::cli {

struct ClipFlags {
  std::string move = "auto";
  std::string effect = "auto";
  uint64_t seed = 1;
  std::string shot;                // a shot file (pipeline/direct/SHOT_FORMAT.md)
  std::vector<double> subject_px;  // x y w h, repeated: user subjects in the centre view
  bool no_faces = false;
  double duration_s = 5.0;
  double fps = 30.0;
  std::string style = "once";
  std::string ease = "smooth";
  double hold_s = 0;
  std::string size;               // "WxH"; "" = from --aspect and --height
  std::string aspect = "source";  // "16:9", "9:16", "1:1", "4:5", ... or source
  int height = 0;                 // with --aspect: the output's height; 0 = the capture's
  std::string format = "auto";
  int crf = 20;
  std::string preset = "veryfast";
  int loop_count = 0;
  int webp_quality = 80;
  std::string quality = "preview";
  std::string gl = "auto";
  std::string depth_mode = "auto";  // auto, standard, light-field (pipeline/depth/depth_mode.h)
  int threads = 0;
  int max_photo_side_px = PipelineOptions{}.image_set_max_side_px;
};

// Adds the flags to `command`, bound to `flags`; returns them (for a command that passes on the
// ones a user gave).
std::vector<CLI::Option*> AddClipFlags(CLI::App& command, ClipFlags& flags);

// The job's options from the flags, checked; `format` is the clip's container (the caller
// resolves --format auto). Face detection is not loaded here (LoadFaceDetectorUnlessOff).
StatusOr<device::ClipJobOptions> ClipJobOptionsFromFlags(const ClipFlags& flags, clip::ClipFormat format);

// Gives `options` the face detector unless --no-faces; a detector that cannot load is a warning.
void LoadFaceDetectorUnlessOff(const ClipFlags& flags, device::ClipJobOptions& options);

}  // namespace px::cli
