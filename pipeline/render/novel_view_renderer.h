// Renders the scene from a virtual camera, given views with depth (paper section 6, on the CPU).
// Per frame: the nearest source views are forward-warped into the target as small quads with a
// z-buffer each (quads stretched across a depth discontinuity are dropped, so disocclusions
// become holes instead of rubber sheets); a soft z-buffer keeps, per pixel, the sources that see
// the nearest surface; their colours are sampled backwards (bilinear) and blended by view
// proximity and depth confidence; uncovered pixels are filled (hole_fill.h).
#pragma once

#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"
#include "pipeline/core/view.h"
#include "pipeline/render/render_options.h"

namespace px {

struct RenderResult {
  cv::Mat bgr;          // CV_8UC3, the target camera's size, holes filled
  cv::Mat depth_m;      // CV_32F, z in the target camera (holes: filled from the background)
  cv::Mat coverage;     // CV_8U, 255 where some source covered the pixel before hole filling
  double hole_ratio = 0;  // fraction of pixels no source covered
  double hole_score = 0;  // the paper's H(V) (k = 3); a viewpoint is valid when below 2
  std::vector<ViewId> sources;  // the source views used, nearest first
};

class NovelViewRenderer {
 public:
  // Keeps (shallow copies of) the views and their depth maps, matched by view id. Views must be
  // undistorted CV_8UC3 images of their camera's size; depth CV_32F of the same size; confidence
  // CV_32F of the same size or empty (then 1).
  static StatusOr<std::unique_ptr<NovelViewRenderer>> Create(const std::vector<View>& views,
                                                             const std::vector<DepthMap>& depths,
                                                             const RenderOptions& options);

  // Renders `target_camera` (pinhole, no distortion) at `target_cam_from_world`. `excluded`
  // leaves one source out (leave-one-out checks). Reuses internal buffers: one call at a time.
  StatusOr<RenderResult> Render(const CameraModel& target_camera, const Rigid3& target_cam_from_world,
                                ViewId excluded = ViewId());

  int NumSources() const { return static_cast<int>(sources_.size()); }

 private:
  struct Source {
    ViewId id;
    cv::Mat image;       // CV_8UC3
    cv::Mat depth_m;     // CV_32F
    cv::Mat confidence;  // CV_32F, or empty
    CameraModel camera;
    Rigid3 cam_from_world;
    Eigen::Vector3d centre_in_world;
  };
  struct Scratch {
    std::vector<cv::Mat> projected;  // per chosen source: CV_32FC3 (x, y, z in the target), z 0 = none
    std::vector<cv::Mat> z_buffer;   // per chosen source: CV_32F target-sized nearest depth, +inf = none
  };

  NovelViewRenderer(std::vector<Source> sources, const RenderOptions& options)
      : sources_(std::move(sources)), options_(options) {}

  std::vector<Source> sources_;
  RenderOptions options_;
  Scratch scratch_;
};

// One-shot convenience: builds a renderer and renders one view.
StatusOr<RenderResult> RenderNovelView(const std::vector<View>& views, const std::vector<DepthMap>& depths,
                                       const CameraModel& target_camera, const Rigid3& target_cam_from_world,
                                       const RenderOptions& options);

}  // namespace px
