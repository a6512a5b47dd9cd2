// Streams BGR frames into an H.264 MP4 (yuv420p, +faststart) that phones and browsers play,
// with libavcodec's libx264. Frames are encoded as they arrive, so a clip never sits in memory.
#pragma once

#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "pipeline/clip/clip_writer.h"
#include "pipeline/core/status.h"

namespace px::clip {

struct Mp4Options {
  double fps = 30.0;                // frames per second, (0, 240]
  int crf = 20;                     // x264 constant rate factor, [0, 51]; lower is better and larger
  std::string preset = "veryfast";  // x264 preset: ultrafast .. veryslow
  Status Validate() const;
};

class Mp4Writer : public ClipWriter {
 public:
  // Opens `path` for writing frames of width x height (odd sizes are cropped by one pixel:
  // yuv420p needs even sizes). The caller owns atomicity: write to a temporary name, then rename.
  static StatusOr<std::unique_ptr<Mp4Writer>> Open(const std::filesystem::path& path,
                                                   int width,
                                                   int height,
                                                   const Mp4Options& options);

 protected:
  using ClipWriter::ClipWriter;
};

}  // namespace px::clip
