#include "eval/datasets/middlebury_stereo.h"

#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "pipeline/core/size_text.h"

namespace px::eval {
namespace {

namespace fs = std::filesystem;

struct Layout {
  const char* left;
  const char* right;
  const char* gt;
  double scale;  // GT png value / scale = disparity
};

constexpr Layout kLayouts[] = {{"im2.png", "im6.png", "disp2.png", 4.0}, {"view1.png", "view5.png", "disp1.png", 3.0}};

const Layout* FindLayout(const fs::path& dir) {
  for (const Layout& layout : kLayouts) {
    if (fs::exists(dir / layout.left) && fs::exists(dir / layout.right) && fs::exists(dir / layout.gt)) return &layout;
  }
  return nullptr;
}

}  // namespace

bool IsMiddleburyPairDir(const fs::path& dir) { return FindLayout(dir) != nullptr; }

StatusOr<StereoPair> LoadMiddleburyPair(const fs::path& dir) {
  const Layout* layout = FindLayout(dir);
  if (layout == nullptr) {
    return NotFoundError(dir.string() +
                         ": no Middlebury pair (want im2.png, im6.png, disp2.png or view1.png, view5.png, "
                         "disp1.png)");
  }
  const fs::path left_path = dir / layout->left, right_path = dir / layout->right, gt_path = dir / layout->gt;
  const cv::Mat left = cv::imread(left_path.string(), cv::IMREAD_COLOR);
  const cv::Mat right = cv::imread(right_path.string(), cv::IMREAD_COLOR);
  const cv::Mat gt = cv::imread(gt_path.string(), cv::IMREAD_GRAYSCALE);
  if (left.empty()) return DataLossError(left_path.string() + ": unreadable image");
  if (right.empty()) return DataLossError(right_path.string() + ": unreadable image");
  if (gt.empty()) return DataLossError(gt_path.string() + ": unreadable image");
  if (right.size() != left.size()) {
    return DataLossError(right_path.string() + ": " + SizeText(right.cols, right.rows) + ", the left view is " +
                         SizeText(left.cols, left.rows));
  }
  if (gt.size() != left.size()) {
    return DataLossError(gt_path.string() + ": " + SizeText(gt.cols, gt.rows) + ", the left view is " +
                         SizeText(left.cols, left.rows));
  }
  const std::string name = dir.parent_path().filename().string() + "/" + dir.filename().string();
  StereoPair pair = MakeRectifiedPair(
      name, left, right, /*focal_px=*/left.cols, (left.cols - 1) / 2.0, (left.rows - 1) / 2.0, /*baseline_m=*/0.1);
  pair.gt_disparity.create(gt.size(), CV_32F);
  for (int y = 0; y < gt.rows; ++y) {
    for (int x = 0; x < gt.cols; ++x) {
      const uchar value = gt.at<uchar>(y, x);
      pair.gt_disparity.at<float>(y, x) =
          value == 0 ? std::numeric_limits<float>::quiet_NaN() : static_cast<float>(value / layout->scale);
    }
  }
  pair.min_disparity = 0.5;
  pair.max_disparity = 255.0 / layout->scale;
  return pair;
}

}  // namespace px::eval
