// Decodes a looping animation (GIF through libavformat, animated WebP through libwebpdemux,
// which FFmpeg 5.1 cannot decode) and reports what a viewer sees, for the clip-format tests.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace px::testing {

struct AnimationProbe {
  std::string format;  // "gif" or "webp"
  int width = 0;
  int height = 0;
  int frames = 0;
  // Times the animation plays, as clip::ClipOptions::loop_count says it: 0 = forever.
  int plays = -1;
  double duration_s = 0;
  cv::Mat first_frame;  // BGR
  cv::Mat last_frame;   // BGR
};

StatusOr<AnimationProbe> ProbeAnimation(const std::filesystem::path& path);

}  // namespace px::testing
