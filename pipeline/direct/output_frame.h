// The clip's frame: its size and aspect, chosen by the user (a 9:16 story, a 1:1 or 4:5 feed
// post, 1080p) or the centre view's. The output camera covers the widest field of that aspect
// that the centre view saw (a crop, never letterboxing), at the output's resolution, so the
// taxonomy's framing, the subjects-in-frame rules, the valid-viewpoint search and H(V) are all
// evaluated in the frame the viewer will see.
#pragma once

#include <string_view>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/status.h"

namespace px {

struct OutputFrameOptions {
  int width = 0;      // output size in pixels; 0 with height 0 = from aspect and height, else both set
  int height = 0;     // with width 0: the output's height (0 = the centre view's)
  double aspect = 0;  // width / height when width is 0; 0 = the centre view's
  Status Validate() const;
};

// "WxH" -> width, height; "16:9" -> aspect; "source" -> 0. INVALID_ARGUMENT naming the text.
Status ParseOutputSize(std::string_view text, OutputFrameOptions* options);
Status ParseOutputAspect(std::string_view text, OutputFrameOptions* options);

// The output size for a centre view of source_width x source_height: even numbers (H.264).
struct OutputSize {
  int width = 0;
  int height = 0;
};
OutputSize ResolveOutputSize(const OutputFrameOptions& options, int source_width, int source_height);

// The centre view's pinhole camera re-framed to `size`: the widest crop of the output's aspect,
// scaled to its resolution (its principal point keeps its place relative to the frame's centre).
// `scale`: output pixels per source pixel (> 1: the clip is upsampled).
CameraModel FrameOutputCamera(const CameraModel& source, OutputSize size, double* scale);

}  // namespace px
