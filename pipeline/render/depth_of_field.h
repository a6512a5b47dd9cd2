// Depth of field (ALGORITHM.md section 8): the thin lens's circle of confusion; the preview's
// blur by it from a stack of blur levels with the paper's foreground-silhouette correction (6.1);
// and the offline synthetic aperture's viewpoints (6.2).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"

namespace px::render {

// Diameter in output pixels of the blur of a point at depth z_m for a lens of `aperture_m`
// focused at `focus_m`: aperture * focal_px * |1/z - 1/focus|.
double CircleOfConfusionPx(double aperture_m, double focus_m, double focal_px, double z_m);

struct DepthOfFieldReport {
  int levels = 0;             // blur levels built (0: nothing was blurred)
  int silhouette_pixels = 0;  // background pixels given blurred foreground over them
};

// Blurs `colour` (CV_32FC3) in place by each pixel's circle of confusion from `depth` (CV_32F),
// with the foreground-silhouette correction. Blur is capped at a Gaussian sigma of 32 px.
DepthOfFieldReport ApplyPreviewDepthOfField(
    double aperture_m, double focus_m, double focal_px, const cv::Mat& depth, cv::Mat* colour);

// One viewpoint of the synthetic aperture: the camera moved within its lens plane, its principal
// point shifted so that the focal plane at focus_m stays registered.
struct ApertureViewpoint {
  CameraModel camera;
  Rigid3 cam_from_world;
};

// `count` viewpoints on a Vogel spiral over the aperture disc (the first nearest the centre).
std::vector<ApertureViewpoint> ApertureViewpoints(
    const CameraModel& camera, const Rigid3& cam_from_world, double aperture_m, double focus_m, int count);

}  // namespace px::render
