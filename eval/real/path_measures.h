// What a clip's frames show where no ground truth exists (a real capture's automatic path):
//  - torn pixels: thin far gaps in a near surface (the crack measure of eval/render, with the
//    sources' own depth and images as the reference): a pixel rendered far behind both its sides
//    across a gap of at most 3 px, where the sources that see that place show the near surface
//    going on, in a colour other than the one the frame shows there;
//  - double images: the renderer's own count of pixels drawn from a view that a more heavily
//    weighted view contradicts, or blended from views that disagree in colour beyond noise
//    (FrameRender::double_image, in regions: eval/render/image_metrics.h DoubleImageFraction);
//  - flicker: pixels that change by more than noise from one frame to the next once the camera's
//    motion is taken out (the previous frame reprojected through this frame's depth);
//  - holes: the share of each frame no source covered.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/view.h"
#include "pipeline/core/virtual_camera.h"
#include "pipeline/render/scene_renderer.h"

namespace px::eval {

struct TearOptions {
  double far_fraction = 0.1;  // "far behind": depth beyond (1 + this) of the sides
  int max_gap_px = 3;
  int max_sources = 3;  // the frame's heaviest sources consulted
  // A source's image must show a colour more than this far (largest channel) from the frame's
  // there: a gap the source's depth smooths over but its image shows is real, not a tear.
  int colour_levels = 30;
};

// The torn pixels of `frame` (drawn by `camera`) against `views` and their `depth` (one map per
// view, in order); `map` (may be null) receives them (CV_8U, 255).
double TornFraction(const FrameRender& frame,
                    const VirtualCamera& camera,
                    const std::vector<View>& views,
                    const std::vector<DepthMap>& depth,
                    const TearOptions& options = {},
                    cv::Mat* map = nullptr);

// Pixels of `current` (its depth, drawn by `camera`) whose colour differs by more than
// `threshold` levels (any channel) from `previous` (drawn by `previous_camera`) at the same
// scene point; pixels whose point falls outside the previous frame do not count. The share of the
// pixels that count, and when `map` is not null the changing pixels (CV_8U, 255).
double FlickerFraction(const cv::Mat& previous_bgr,
                       const VirtualCamera& previous_camera,
                       const FrameRender& current,
                       const VirtualCamera& camera,
                       int threshold = 40,
                       cv::Mat* map = nullptr);

}  // namespace px::eval
