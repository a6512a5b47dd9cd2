// What both depth methods (the segment stereo of depth_stage.h and the first plane sweep) share:
// views reduced to what matching needs at the working scale, the input checks, and a scoped
// OpenCV thread count.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"
#include "pipeline/core/view.h"

namespace px::depth {

// A view at the working scale.
struct WorkingView {
  cv::Mat bgr;   // CV_8UC3, guide for edge-aware filtering
  cv::Mat gray;  // CV_32F in [0, 1]
  CameraModel camera;
  Rigid3 cam_from_world;
};

// scale in (0, 1]: area-averaged down-sampling, intrinsics scaled to match.
WorkingView MakeWorkingView(const View& view, double scale);

// working_scale raised (up to 1) so that the narrowest view matches on at least min_width_px
// columns; 0 leaves it as given.
double MatchingScale(const std::vector<View>& views, double working_scale, int min_width_px);

std::string ViewName(const View& view);

// Checks what every depth method needs: at least 2 views; undistorted pinhole cameras; CV_8UC3
// images of their camera's size; finite poses; each view large enough at `working_scale` for a
// window of `window_radius_px` with its interpolation margin; and a parallax partner for every
// view. Errors name the view and the value at fault.
Status CheckViews(const std::vector<View>& views, double working_scale, int window_radius_px);

// Sets OpenCV's worker count for the lifetime of the guard (0 leaves it alone).
class ScopedNumThreads {
 public:
  explicit ScopedNumThreads(int num_threads);
  ~ScopedNumThreads();
  ScopedNumThreads(const ScopedNumThreads&) = delete;
  ScopedNumThreads& operator=(const ScopedNumThreads&) = delete;

 private:
  int previous_;
  bool active_;
};

}  // namespace px::depth
