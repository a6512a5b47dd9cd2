// One input viewpoint: an image with its camera and pose.
#pragma once

#include <cstdint>
#include <limits>
#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"

namespace px {

// Index of a view in its shot (row-major lattice order, or the order of an image set).
struct ViewId {
  static constexpr int32_t kInvalidValue = -1;
  int32_t value = kInvalidValue;
  bool valid() const { return value != kInvalidValue; }
  friend bool operator==(ViewId a, ViewId b) = default;
  friend auto operator<=>(ViewId a, ViewId b) = default;
};

struct View {
  ViewId id;
  cv::Mat image;          // CV_8UC3, BGR, camera.width x camera.height
  CameraModel camera;     // intrinsics of `image` (distortion zero once undistorted)
  Rigid3 cam_from_world;  // world = the rig frame for a lattice camera
};

// Per-view depth: z in the camera frame (metres), 0 where unknown.
struct DepthMap {
  ViewId id;
  cv::Mat depth_m;     // CV_32F
  cv::Mat confidence;  // CV_32F in [0, 1]
};

}  // namespace px
