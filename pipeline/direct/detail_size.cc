#include "pipeline/direct/detail_size.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace px::direct {

VirtualCamera CameraAtDetail(const VirtualCamera& camera, double output_scale) {
  if (!(output_scale > kDrawAtDetailAbove)) return camera;
  VirtualCamera small = camera;
  CameraModel& model = small.camera;
  model.width = std::max(2, static_cast<int>(std::lround(camera.camera.width / output_scale)));
  model.height = std::max(2, static_cast<int>(std::lround(camera.camera.height / output_scale)));
  // Per axis, the ratio of the whole sizes: cv::resize maps an output pixel centre x to
  // (x + 0.5) * small / large - 0.5, so the small camera's pixel centres sit exactly there.
  const double sx = static_cast<double>(model.width) / camera.camera.width;
  const double sy = static_cast<double>(model.height) / camera.camera.height;
  model.fx = camera.camera.fx * sx;
  model.fy = camera.camera.fy * sy;
  model.cx = (camera.camera.cx + 0.5) * sx - 0.5;
  model.cy = (camera.camera.cy + 0.5) * sy - 0.5;
  return small;
}

cv::Mat EnlargeToOutput(const cv::Mat& drawn, int width, int height) {
  if (drawn.cols == width && drawn.rows == height) return drawn;
  cv::Mat large;
  cv::resize(drawn, large, cv::Size(width, height), 0, 0, cv::INTER_CUBIC);
  return large;
}

}  // namespace px::direct
