// Test-only: the small scenes of known depth that the depth stage's tests share (a textured
// square before a textured wall, seen by a 3x3 rig of 320x240 lenses) and how they score.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/view.h"
#include "pipeline/depth/depth_options.h"
#include "pipeline/depth/plane_scene_test_util.h"

namespace px::depth::testing {

constexpr double kStageBaselineM = 0.03;
constexpr double kStageFocalPx = 300.0;
CameraModel SmallCamera();  // 320x240, kStageFocalPx

// Depth range 0.5 .. 8 m, matching at full resolution.
DepthOptions StageTestOptions();

// An infinite textured wall at depth_m, one texel per pixel of SmallCamera at that depth.
TexturedPlane Wall(double depth_m, uint64_t seed);

// A textured square at 1 m (90 x 72 px in the centre view) before a textured wall at 3 m, seen
// by a 3x3 rig with kStageBaselineM spacing; truth gets each view's true depth.
std::vector<View> SquareBeforeWall(std::vector<cv::Mat>* truth, uint64_t wall_seed = 21);

// SquareBeforeWall seen from one view (the centre, index 4, unless told) by the other eight, for
// steps that refine one view against its neighbours.
struct SquareFromView {
  static constexpr int kCentre = 4;
  static constexpr double kSquareDepthM = 1.0, kWallDepthM = 3.0;
  int reference = kCentre;
  std::vector<View> views;
  cv::Mat square;  // 255 where the reference view sees the square
  std::vector<const View*> Neighbours() const;
  // Inverse depth (1/m) of one pixel of disparity against the nearest neighbour.
  static double PixelInverseDepth() { return 1.0 / (kStageFocalPx * kStageBaselineM); }
};
SquareFromView MakeSquareFromView(int reference = SquareFromView::kCentre);

// Fraction of pixels (where mask != 0 and truth > 0) off by more than `relative` of the truth.
double BadFraction(const cv::Mat& depth_m, const cv::Mat& truth, const cv::Mat& mask, double relative);

// 255 within radius_px of a jump in the true depth.
cv::Mat NearEdges(const cv::Mat& truth, int radius_px);

}  // namespace px::depth::testing
