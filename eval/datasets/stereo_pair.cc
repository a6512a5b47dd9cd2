#include "eval/datasets/stereo_pair.h"

#include <utility>

namespace px::eval {

StereoPair MakeRectifiedPair(std::string name,
                             const cv::Mat& left_bgr,
                             const cv::Mat& right_bgr,
                             double focal_px,
                             double cx,
                             double cy,
                             double baseline_m) {
  StereoPair pair;
  pair.name = std::move(name);
  pair.focal_px = focal_px;
  pair.baseline_m = baseline_m;
  CameraModel camera = CameraModel::Pinhole(left_bgr.cols, left_bgr.rows, focal_px);
  camera.cx = cx;
  camera.cy = cy;
  pair.left.id = ViewId{0};
  pair.left.image = left_bgr;
  pair.left.camera = camera;
  pair.left.cam_from_world = Rigid3();
  pair.right.id = ViewId{1};
  pair.right.image = right_bgr;
  pair.right.camera = camera;
  // The right camera's centre is at (+baseline, 0, 0): p_in_right = p_in_world - centre.
  pair.right.cam_from_world = Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-baseline_m, 0, 0));
  return pair;
}

}  // namespace px::eval
