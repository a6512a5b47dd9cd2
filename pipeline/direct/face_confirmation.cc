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
  const Eigen::Vector3d centre_camera = CameraCentre(centre.cam_from_world);
  std::vector<int> others;
  for (int i = 0; i < static_cast<int>(views.size()); ++i) {
    if (i != centre_index && !views[i].image.empty()) others.push_back(i);
  }
  const auto distance = [&](int i) { return (CameraCentre(views[i].cam_from_world) - centre_camera).norm(); };
  std::stable_sort(others.begin(), others.end(), [&](int a, int b) { return distance(a) < distance(b); });
  const Eigen::Vector3d point = face.CentreInWorld();
  const int centre_side = std::max(centre.image.cols, centre.image.rows);
  for (const int index : others) {
    if (result.views_checked == kMaxConfirmingViews) break;
    const View& other = views[index];
    const Eigen::Vector3d in_other = other.cam_from_world * point;
    Eigen::Vector2d pixel;
    if (!other.camera.Project(in_other, &pixel)) continue;  // behind it
    // The face's width there: its width in the centre view scaled by depth and focal length.
    const double expected = face.box_px.width * (face.depth_m / in_other.z()) * (other.camera.fx / centre.camera.fx);
    const int half = static_cast<int>(std::ceil(2 * expected));
    const cv::Rect window = cv::Rect(static_cast<int>(std::lround(pixel.x())) - half,
                                     static_cast<int>(std::lround(pixel.y())) - half,
                                     2 * half,
                                     2 * half) &
                            cv::Rect(0, 0, other.image.cols, other.image.rows);
    // The face must lie in the image there to be judged.
    if (pixel.x() < 0 || pixel.y() < 0 || pixel.x() >= other.image.cols || pixel.y() >= other.image.rows ||
        window.width < expected || window.height < expected) {
      continue;
    }
    ++result.views_checked;
    FaceDetectionOptions crop_options = options;
    crop_options.frame_filling = false;  // the face is a quarter of the window, not larger than it
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
