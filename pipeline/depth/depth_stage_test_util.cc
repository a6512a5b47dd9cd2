#include "pipeline/depth/depth_stage_test_util.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace px::depth::testing {

CameraModel SmallCamera() { return CameraModel::Pinhole(320, 240, kStageFocalPx); }

DepthOptions StageTestOptions() {
  DepthOptions options;
  options.min_depth_m = 0.5;
  options.max_depth_m = 8.0;
  options.working_scale = 1.0;
  return options;
}

TexturedPlane Wall(double depth_m, uint64_t seed) {
  TexturedPlane wall;
  wall.depth_m = depth_m;
  wall.metres_per_texel = depth_m / kStageFocalPx;
  wall.texture = RandomTexture(cv::Size(480, 400), seed);
  return wall;
}

std::vector<View> SquareBeforeWall(std::vector<cv::Mat>* truth, uint64_t wall_seed) {
  TexturedPlane square;
  square.depth_m = 1.0;
  square.extent_m = cv::Rect2d(-0.15, -0.12, 0.3, 0.24);
  square.metres_per_texel = 1.0 / kStageFocalPx;
  square.texture = RandomTexture(cv::Size(100, 80), 22);
  return RenderGridRig(3, 3, kStageBaselineM, SmallCamera(), {square, Wall(3.0, wall_seed)}, truth);
}

std::vector<const View*> SquareFromView::Neighbours() const {
  std::vector<const View*> neighbours;
  for (size_t i = 0; i < views.size(); ++i) {
    if (static_cast<int>(i) != reference) neighbours.push_back(&views[i]);
  }
  return neighbours;
}

SquareFromView MakeSquareFromView(int reference) {
  SquareFromView scene;
  scene.reference = reference;
  std::vector<cv::Mat> truth;
  scene.views = SquareBeforeWall(&truth);
  const double between_m = 0.5 * (SquareFromView::kSquareDepthM + SquareFromView::kWallDepthM);
  scene.square = truth[reference] < between_m;
  return scene;
}

double BadFraction(const cv::Mat& depth_m, const cv::Mat& truth, const cv::Mat& mask, double relative) {
  int bad = 0, total = 0;
  for (int y = 0; y < truth.rows; ++y) {
    for (int x = 0; x < truth.cols; ++x) {
      if (!mask.at<uint8_t>(y, x) || truth.at<float>(y, x) <= 0) continue;
      ++total;
      bad += std::abs(depth_m.at<float>(y, x) - truth.at<float>(y, x)) > relative * truth.at<float>(y, x);
    }
  }
  return total > 0 ? static_cast<double>(bad) / total : 1.0;
}

cv::Mat NearEdges(const cv::Mat& truth, int radius_px) {
  cv::Mat grad_x, grad_y;
  cv::Sobel(truth, grad_x, CV_32F, 1, 0);
  cv::Sobel(truth, grad_y, CV_32F, 0, 1);
  cv::Mat edges = (cv::abs(grad_x) + cv::abs(grad_y)) > 0.1;
  cv::dilate(edges, edges, cv::Mat(), cv::Point(-1, -1), radius_px);
  return edges;
}

}  // namespace px::depth::testing
