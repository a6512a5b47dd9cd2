#include "pipeline/calib/undistort_cache.h"

#include <opencv2/calib3d.hpp>

namespace px {

bool SameCamera(const CameraModel& a, const CameraModel& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy && a.cx == b.cx && a.cy == b.cy &&
         a.distortion == b.distortion;
}

const UndistortCache::Maps& UndistortCache::Get(const CameraModel& camera) {
  for (const Entry& entry : entries_) {
    if (SameCamera(entry.camera, camera)) return entry.maps;
  }
  Entry entry;
  entry.camera = camera;
  const cv::Mat k(camera.CvK());
  // New camera matrix = K: the output is the same pinhole camera, only without distortion.
  cv::initUndistortRectifyMap(k,
                              camera.CvDistortion(),
                              cv::Mat(),
                              k,
                              cv::Size(camera.width, camera.height),
                              CV_32FC1,
                              entry.maps.map_x,
                              entry.maps.map_y);
  entries_.push_back(std::move(entry));
  return entries_.back().maps;
}

}  // namespace px
