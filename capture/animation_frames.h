// The frames of an animated GIF or WebP: a wigglegram (a rig of cameras or a multi-lens film
// camera, each frame one view, often played back and forth). FFmpeg reads GIF; animated WebP,
// which FFmpeg 5.1 cannot decode, comes through libwebp's demux API.
#pragma once

#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/status.h"

namespace px {

// Every frame as shown (composited onto the canvas), BGR, in playing order. Errors name the file
// (DATA_LOSS): neither a GIF nor a WebP by its bytes, a file the decoder refuses or that breaks
// off before its first frame.
StatusOr<std::vector<cv::Mat>> ReadAnimationFrames(const std::filesystem::path& file);

// The frames that do not repeat an earlier one (a back-and-forth loop shows views 0 1 2 3 2 1:
// the views are 0 1 2 3). Two frames repeat when their pixels differ by at most `levels` on
// average (a lossy animation encodes a repeated view again, a little differently).
std::vector<cv::Mat> WithoutRepeatedFrames(const std::vector<cv::Mat>& frames, double levels = 3.0);

}  // namespace px
