// Test-only helpers for the render tests and benchmark: the analytic two-plane scene's lattice as
// layered views (exact depth through LayeredDepthFromDepthMap), masked PSNR, and the mask of pixels
// away from depth edges.
#pragma once

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <utility>
#include <vector>

#include "pipeline/core/layered_depth.h"
#include "pipeline/core/view.h"
#include "pipeline/render/layered_from_depth.h"
#include "pipeline/render/plane_scene_testing.h"

namespace px::render::testing {

// The views and their layered depth for a rows x cols lattice of `scene` (exact depth).
inline void MakeLayeredLattice(const PlaneScene& scene,
                               int rows,
                               int cols,
                               double baseline_m,
                               const CameraModel& camera,
                               std::vector<View>* views,
                               std::vector<LayeredDepthView>* layers,
                               const LayeredFromDepthOptions& options = {}) {
  std::vector<DepthMap> depths;
  MakeLatticeViews(scene, rows, cols, baseline_m, camera, views, &depths);
  layers->clear();
  for (size_t i = 0; i < views->size(); ++i) {
    layers->push_back(LayeredDepthFromDepthMap((*views)[i], depths[i], options).value());
  }
}

// The benchmarks' shot: the two-plane scene seen by 9 views (3x3, 25 mm) or 20 (5x4, 12.5 mm)
// of width x (2/3 width) pixels, f = 0.875 width. Built once per (width, views) and kept:
// building 20 views of 1200x800 takes seconds.
struct LatticeShot {
  std::vector<View> views;
  std::vector<LayeredDepthView> layers;
  CameraModel camera;
};
inline const LatticeShot& CachedLatticeShot(int width, int num_views) {
  static std::map<std::pair<int, int>, std::unique_ptr<LatticeShot>> shots;
  auto& shot = shots[{width, num_views}];
  if (!shot) {
    shot = std::make_unique<LatticeShot>();
    shot->camera = CameraModel::Pinhole(width, width * 2 / 3, 0.875 * width);
    const int rows = num_views == 9 ? 3 : 4, cols = num_views == 9 ? 3 : 5;
    const double baseline_m = num_views == 9 ? 0.025 : 0.0125;
    PlaneScene scene;
    MakeLayeredLattice(scene, rows, cols, baseline_m, shot->camera, &shot->views, &shot->layers);
  }
  return *shot;
}

// PSNR over the pixels where `mask` is non-zero (all when empty), 99 when identical.
inline double MaskedPsnr(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask = cv::Mat()) {
  double total = 0;
  long count = 0;
  for (int y = 0; y < a.rows; ++y) {
    for (int x = 0; x < a.cols; ++x) {
      if (!mask.empty() && mask.at<uint8_t>(y, x) == 0) continue;
      const cv::Vec3b p = a.at<cv::Vec3b>(y, x), q = b.at<cv::Vec3b>(y, x);
      for (int c = 0; c < 3; ++c) {
        const double d = static_cast<double>(p[c]) - q[c];
        total += d * d;
      }
      count += 3;
    }
  }
  const double mse = total / static_cast<double>(std::max(count, 1L));
  return mse <= 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

// Pixels more than 2 px from a depth discontinuity (over 10 %) of an exact depth map: silhouettes
// are defined to about a pixel by point sampling, so errors there measure sampling, not geometry.
inline cv::Mat AwayFromEdges(const cv::Mat& depth_m) {
  cv::Mat edges(depth_m.size(), CV_8U, cv::Scalar(0));
  for (int y = 0; y < depth_m.rows; ++y) {
    for (int x = 0; x < depth_m.cols; ++x) {
      const float z = depth_m.at<float>(y, x);
      const float right = depth_m.at<float>(y, std::min(x + 1, depth_m.cols - 1));
      const float down = depth_m.at<float>(std::min(y + 1, depth_m.rows - 1), x);
      if (std::abs(z - right) > 0.1f * z || std::abs(z - down) > 0.1f * z) edges.at<uint8_t>(y, x) = 255;
    }
  }
  cv::dilate(edges, edges, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)));
  return edges == 0;
}

}  // namespace px::render::testing
