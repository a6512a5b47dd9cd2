#include "pipeline/direct/splat_coverage.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace px::direct {

namespace {

// Splats are this much wider than the patch each point stands for: neighbouring points of a
// surface seen obliquely lie farther apart than their patches, and a crack one target pixel wide
// reads as a hole.
constexpr float kFootprint = 1.5f;

}  // namespace

double HoleScoreAtOutputSize(const cv::Mat& covered, double scale) {
  const cv::Mat holes = covered == 0;
  const int hole_pixels = cv::countNonZero(holes);
  if (hole_pixels == 0) return 0.0;
  const double area = static_cast<double>(covered.total());
  if (hole_pixels == static_cast<int>(covered.total())) {
    return std::pow(std::hypot(covered.cols, covered.rows) / scale, 3);  // nothing covered
  }
  cv::Mat distance;  // to the nearest covered pixel, in target pixels
  cv::distanceTransform(holes, distance, cv::DIST_L2, cv::DIST_MASK_5);
  cv::Mat at_output = (distance - 0.5) / scale + 0.5;
  cv::pow(at_output, 3, at_output);
  return cv::mean(at_output, holes)[0] * hole_pixels / area;
}

SplatCoverage SplatCoverage::FromDepths(const std::vector<View>& views,
                                        const std::vector<DepthMap>& depths,
                                        double scale,
                                        int stride) {
  SplatCoverage splat;
  splat.samples_ = SceneSamples::FromDepths(views, depths, stride);
  splat.scale_ = std::clamp(scale, 1e-3, 1.0);
  return splat;
}

CoverageReport SplatCoverage::Measure(const CameraModel& camera, const Rigid3& cam_from_world) const {
  const CameraModel target = camera.Scaled(scale_);
  const cv::Mat covered = samples_.DepthSeenFrom(target, cam_from_world, kFootprint) > 0;
  CoverageReport report;
  report.width = camera.width;
  report.height = camera.height;
  report.hole_ratio = 1.0 - cv::countNonZero(covered) / static_cast<double>(covered.total());
  report.hole_score = HoleScoreAtOutputSize(covered, static_cast<double>(covered.cols) / camera.width);
  return report;
}

CoverageFunction SplatCoverage::AsFunction() const {
  return [this](const CameraModel& camera, const Rigid3& cam_from_world) -> StatusOr<CoverageReport> {
    return Measure(camera, cam_from_world);
  };
}

}  // namespace px::direct
