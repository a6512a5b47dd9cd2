// Undistortion maps, computed once per distinct camera and reused: a rig's calibration rarely
// changes between shots, and lenses with identical intrinsics share one pair of maps.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/camera_model.h"

namespace px {

// Keeps the remap tables for each distinct CameraModel seen. Not thread-safe: use one per thread,
// or guard it. Memory: two float maps per distinct camera (8 bytes per pixel).
class UndistortCache {
 public:
  struct Maps {
    cv::Mat map_x;  // CV_32FC1: for each undistorted pixel, where to sample the distorted tile
    cv::Mat map_y;  // CV_32FC1
  };

  // The maps that turn an image taken by `camera` into the image of the same pinhole camera
  // (same K) without distortion. Computed with cv::initUndistortRectifyMap on first use.
  const Maps& Get(const CameraModel& camera);

  int NumCached() const { return static_cast<int>(entries_.size()); }
  void Clear() { entries_.clear(); }

 private:
  struct Entry {
    CameraModel camera;
    Maps maps;
  };
  std::vector<Entry> entries_;  // a handful of cameras at most: a linear search is fastest
};

// True when both models describe exactly the same camera (every field bit-identical).
bool SameCamera(const CameraModel& a, const CameraModel& b);

}  // namespace px
