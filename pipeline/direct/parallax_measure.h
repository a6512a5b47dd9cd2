// The paper's parallax measure (4.2.2): "the most perceptually noticeable areas of parallax are
// those that are visible in one viewpoint and occluded in the other". Each endpoint sees the
// scene as a z-buffer of the views' depth points; a point one endpoint sees is counted when it
// projects inside the other endpoint's frame behind a nearer surface there. The score is the
// counted area in both directions as a fraction of the frame. Content that merely enters or
// leaves the frame (a pan) is not parallax and does not count.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/view.h"

namespace px::direct {

class SceneSamples {
 public:
  // Every `stride`-th pixel of every view with confident depth (confidence >= 0.5 where a
  // confidence map is given), as world points with the size of the patch each stands for.
  static SceneSamples FromDepths(const std::vector<View>& views, const std::vector<DepthMap>& depths, int stride = 4);

  // z-buffer of the points seen by `camera` at `cam_from_world`: CV_32F, z in that camera,
  // 0 where no point lands. Each point covers its patch's projected size times `footprint`
  // (1 to 6 pixels).
  cv::Mat DepthSeenFrom(const CameraModel& camera, const Rigid3& cam_from_world, float footprint = 1.0f) const;

  size_t size() const { return points_.size(); }

 private:
  std::vector<Eigen::Vector3f> points_;
  std::vector<float> patch_m_;  // side of the patch each point stands for, metres
};

// Fraction of the frame (both directions summed, so up to 2) visible from one endpoint and
// occluded from the other; `camera_a`/`camera_b` should be small (a quarter of the output size
// is plenty). A surface counts as occluded behind one more than `relative_gap` nearer.
double ParallaxScore(const SceneSamples& samples,
                     const CameraModel& camera_a,
                     const Rigid3& cam_a_from_world,
                     const CameraModel& camera_b,
                     const Rigid3& cam_b_from_world,
                     double relative_gap = 0.05);
// The same from the endpoints' z-buffers (SceneSamples::DepthSeenFrom with footprint 1), for
// endpoints shared by several candidate paths.
double ParallaxScore(const cv::Mat& depth_a,
                     const CameraModel& camera_a,
                     const Rigid3& cam_a_from_world,
                     const cv::Mat& depth_b,
                     const CameraModel& camera_b,
                     const Rigid3& cam_b_from_world,
                     double relative_gap = 0.05);

}  // namespace px::direct
