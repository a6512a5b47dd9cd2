// Decodes a video file completely with libavformat/libavcodec and reports what a player sees.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

#include "pipeline/core/status.h"

namespace px::testing {

struct VideoProbe {
  std::string container;     // "mov,mp4,m4a,3gp,3g2,mj2"
  std::string codec;         // "h264"
  std::string pixel_format;  // "yuv420p"
  int width = 0;
  int height = 0;
  int frames_decoded = 0;
  double fps = 0;
  double duration_s = 0;          // from the container
  bool moov_before_mdat = false;  // faststart: the index precedes the media data
  cv::Mat first_frame;            // BGR
  cv::Mat last_frame;             // BGR
};

StatusOr<VideoProbe> ProbeVideo(const std::filesystem::path& path);

}  // namespace px::testing
