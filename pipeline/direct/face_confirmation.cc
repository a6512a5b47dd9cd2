#include "pipeline/direct/face_confirmation.h"

#include <algorithm>
#include <cmath>

namespace px::direct {

FaceConfirmation ConfirmFace(const Subject& face,
                             const std::vector<View>& views,
                             int centre_index,
                             const FaceDetector& detector,
                             const FaceDetectionOptions& options) {
  FaceConfirmation result;
  const View& centre = views[centre_index];
  const Eigen::Vector3d centre_camera = centre.cam_from_world.Inverse().translation;
  std::vector<int> others;
  for (int i = 0; i < static_cast<int>(views.size()); ++i) {
    if (i != centre_index && !views[i].image.empty()) others.push_back(i);
  }
  std::stable_sort(others.begin(), others.end(), [&](int a, int b) {
    return (views[a].cam_from_world.Inverse().translation - centre_camera).norm() <
           (views[b].cam_from_world.Inverse().translation - centre_camera).norm();
  });
  const Eigen::Vector3d point = face.CentreInWorld();
  const int centre_side = std::max(centre.image.cols, centre.image.rows);
  for (const int index : others) {
    if (result.views_checked == kMaxConfirmingViews) break;
    const View& other = views[index];
    const Eigen::Vector3d in_other = other.cam_from_world * point;
    Eigen::Vector2d pixel;
    if (!(in_other.z() > 0) || !other.camera.Project(in_other, &pixel)) continue;
    // The face's width there: its width in the centre view scaled by depth and focal length.
    const double expected = face.box_px.width * (face.depth_m / in_other.z()) * (other.camera.fx / centre.camera.fx);
    const cv::Rect2d window_d(pixel.x() - 2 * expected, pixel.y() - 2 * expected, 4 * expected, 4 * expected);
    const cv::Rect window =
        cv::Rect(
            cv::Point(static_cast<int>(std::floor(window_d.x)), static_cast<int>(std::floor(window_d.y))),
            cv::Point(static_cast<int>(std::ceil(window_d.br().x)), static_cast<int>(std::ceil(window_d.br().y)))) &
        cv::Rect(0, 0, other.image.cols, other.image.rows);
    // The face must lie in the image there to be judged.
    if (pixel.x() < 0 || pixel.y() < 0 || pixel.x() >= other.image.cols || pixel.y() >= other.image.rows ||
        window.width < expected || window.height < expected) {
      continue;
    }
    ++result.views_checked;
    FaceDetectionOptions crop_options = options;
    crop_options.min_face_px = std::clamp(static_cast<int>(0.5 * expected), 8, options.min_face_px);
    // The centre view's search scale: upscaled as it was, or not at all.
    crop_options.upscale_below_px =
        centre_side < options.upscale_below_px
            ? static_cast<int>(std::lround(std::max(window.width, window.height) *
                                           (static_cast<double>(options.upscale_below_px) / centre_side)))
            : 0;
    const std::vector<FaceBox> found = detector.Detect(other.image(window), crop_options);
    for (const FaceBox& box : found) {
      const double cx = window.x + box.box.x + 0.5 * box.box.width, cy = window.y + box.box.y + 0.5 * box.box.height;
      const double ratio = box.box.width / expected;
      if (std::hypot(cx - pixel.x(), cy - pixel.y()) <= expected && ratio >= 0.5 && ratio <= 2.0) {
        result.confirming_view = other.id.value;
        break;
      }
    }
    result.detail += (result.detail.empty() ? "" : ", ") + std::string("view ") + std::to_string(other.id.value) +
                     (result.confirming_view == other.id.value ? " (found)" : " (not found)");
    if (result.confirming_view >= 0) break;
  }
  if (result.detail.empty()) result.detail = "no other view sees where it lies";
  return result;
}

}  // namespace px::direct
