#include "pipeline/depth/working_view.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "pipeline/depth/plane_homography.h"

namespace px::depth {

WorkingView MakeWorkingView(const View& view, double scale) {
  WorkingView working;
  working.cam_from_world = view.cam_from_world;
  if (scale < 1) {
    working.camera = view.camera.Scaled(scale);
    cv::resize(view.image, working.bgr, cv::Size(working.camera.width, working.camera.height), 0, 0, cv::INTER_AREA);
  } else {
    working.camera = view.camera;
    working.bgr = view.image;
  }
  cv::Mat gray8;
  cv::cvtColor(working.bgr, gray8, cv::COLOR_BGR2GRAY);
  gray8.convertTo(working.gray, CV_32F, 1.0 / 255.0);
  return working;
}

double MatchingScale(const std::vector<View>& views, double working_scale, int min_width_px) {
  double scale = working_scale;
  for (const View& view : views) {
    if (view.camera.width > 0)
      scale = std::max(scale, std::min(1.0, min_width_px / static_cast<double>(view.camera.width)));
  }
  return scale;
}

std::string ViewName(const View& view) { return "view " + std::to_string(view.id.value); }

Status CheckViews(const std::vector<View>& views, double working_scale, int window_radius_px) {
  if (views.size() < 2) {
    return InvalidArgumentError("depth needs at least 2 views, got " + std::to_string(views.size()));
  }
  for (const View& view : views) {
    PX_RETURN_IF_ERROR(view.camera.Validate().WithContext(ViewName(view)));
    if (view.camera.HasDistortion()) {
      return InvalidArgumentError(ViewName(view) + ": camera has lens distortion; depth needs undistorted views");
    }
    if (view.image.type() != CV_8UC3 || view.image.cols != view.camera.width || view.image.rows != view.camera.height) {
      std::ostringstream error;
      error << ViewName(view) << ": image is " << view.image.cols << "x" << view.image.rows << " with "
            << view.image.channels() << " channels, want " << view.camera.width << "x" << view.camera.height
            << " CV_8UC3";
      return InvalidArgumentError(error.str());
    }
    if (!view.cam_from_world.translation.allFinite() || !view.cam_from_world.rotation.coeffs().allFinite()) {
      return InvalidArgumentError(ViewName(view) + ": pose is not finite");
    }
  }
  // The working image must hold a matching window with its interpolation margin.
  const int min_side = 2 * (window_radius_px + 2) + 1;
  for (const View& view : views) {
    const CameraModel working = working_scale < 1 ? view.camera.Scaled(working_scale) : view.camera;
    if (working.width < min_side || working.height < min_side) {
      std::ostringstream error;
      error << ViewName(view) << ": " << view.camera.width << "x" << view.camera.height << " at working scale "
            << working_scale << " is " << working.width << "x" << working.height << ", smaller than " << min_side << "x"
            << min_side << " (window radius " << window_radius_px << ")";
      return InvalidArgumentError(error.str());
    }
  }
  for (int i = 0; i < static_cast<int>(views.size()); ++i) {
    if (NearestNeighbourViews(views, i, 1).empty()) {
      return InvalidArgumentError(ViewName(views[i]) + ": every other view has the same camera centre (no parallax)");
    }
  }
  return OkStatus();
}

// Only a change calls setNumThreads: it rebuilds OpenCV's worker pool, which must not happen while
// another thread (the pipeline's face detection) is inside cv::parallel_for_.
ScopedNumThreads::ScopedNumThreads(int num_threads)
    : previous_(cv::getNumThreads()), active_(num_threads > 0 && num_threads != previous_) {
  if (active_) cv::setNumThreads(num_threads);
}

ScopedNumThreads::~ScopedNumThreads() {
  if (active_) cv::setNumThreads(previous_);
}

}  // namespace px::depth
