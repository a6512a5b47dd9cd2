#include "pipeline/render/hole_views.h"

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/check.h"
#include "pipeline/render/hole_fill.h"
#include "pipeline/render/segment_raster.h"

namespace px::render {
namespace {

// A view's camera as seen from the novel one: p_in_view = rotation * p_in_novel + translation,
// then its intrinsics.
struct ViewFromNovel {
  int view = 0;
  double distance_m = 0;  // between the centres of projection
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  const CameraModel* camera = nullptr;

  // Whether the point lies in front of the view and inside its image (pixel centres' extent).
  bool Sees(const Eigen::Vector3d& p_in_novel) const {
    const Eigen::Vector3d p = rotation * p_in_novel + translation;
    if (!(p.z() > 0)) return false;
    const double u = camera->fx * p.x() / p.z() + camera->cx, v = camera->fy * p.y() / p.z() + camera->cy;
    return u >= -0.5 && v >= -0.5 && u <= camera->width - 0.5 && v <= camera->height - 0.5;
  }
};

// The scene's views ordered by the distance of their centres from the novel camera's.
std::vector<ViewFromNovel> ViewsByDistance(const LayeredScene& scene, const Rigid3& cam_from_world) {
  const Rigid3 world_from_novel = cam_from_world.Inverse();
  const Eigen::Vector3d novel_centre = CameraCentre(cam_from_world);
  std::vector<ViewFromNovel> views;
  for (size_t v = 0; v < scene.views().size(); ++v) {
    const SceneView& view = scene.views()[v];
    const Rigid3 view_from_novel = view.cam_from_world * world_from_novel;
    ViewFromNovel out;
    out.view = static_cast<int>(v);
    out.distance_m = (CameraCentre(view.cam_from_world) - novel_centre).norm();
    out.rotation = view_from_novel.RotationMatrix();
    out.translation = view_from_novel.translation;
    out.camera = &view.camera;
    views.push_back(out);
  }
  std::stable_sort(views.begin(), views.end(), [](const ViewFromNovel& a, const ViewFromNovel& b) {
    return a.distance_m < b.distance_m;
  });
  return views;
}

// Whether the mesh could blend `view` at a pixel with these slots (a witness was never blended).
bool InSlots(const ViewSlots& slots, int view) {
  for (int k = 0; k < 3; ++k) {
    if (slots.view[k] == view && k != slots.witness) return true;
  }
  return false;
}

}  // namespace

std::vector<ViewSlots> OtherViewSlots(const LayeredScene& scene,
                                      const CameraModel& camera,
                                      const Rigid3& cam_from_world,
                                      const std::vector<ViewSlots>& slots,
                                      const cv::Mat& holes,
                                      const cv::Rect& crop) {
  PX_CHECK(holes.type() == CV_8U && holes.cols == camera.width && holes.rows == camera.height)
      << "OtherViewSlots: holes " << holes.cols << "x" << holes.rows;
  PX_CHECK((crop & cv::Rect(0, 0, camera.width, camera.height)) == crop) << "OtherViewSlots: crop outside the frame";
  std::vector<ViewSlots> out(static_cast<size_t>(crop.width) * crop.height);
  const std::vector<ViewFromNovel> views = ViewsByDistance(scene, cam_from_world);
  // Depths at which a ray is tested: near, far and between (harmonic mean: the middle in pixels).
  const double near_m = scene.near_m(), far_m = std::max(scene.far_m(), scene.near_m());
  const std::array<double, 3> depths_m = {near_m, 2.0 / (1.0 / near_m + 1.0 / far_m), far_m};
  const Eigen::Matrix3d k_inverse = camera.K().inverse();
  // Inverse-distance weights need a floor: a view at the novel centre would take everything.
  const double floor_m = 1e-3;
  cv::parallel_for_(cv::Range(0, crop.height), [&](const cv::Range& range) {
    for (int row = range.start; row < range.end; ++row) {
      const int y = crop.y + row;
      const uint8_t* hole = holes.ptr<uint8_t>(y);
      const ViewSlots* frame_slots = slots.data() + static_cast<size_t>(y) * camera.width;
      ViewSlots* crop_slots = out.data() + static_cast<size_t>(row) * crop.width;
      for (int col = 0; col < crop.width; ++col) {
        const int x = crop.x + col;
        if (hole[x] == 0) continue;
        const Eigen::Vector3d ray = k_inverse * Eigen::Vector3d(x, y, 1);
        ViewSlots& s = crop_slots[col];
        int used = 0;
        float weight_sum = 0;
        for (const ViewFromNovel& view : views) {
          if (used == 3) break;
          if (InSlots(frame_slots[x], view.view)) continue;
          const bool sees = std::any_of(depths_m.begin(), depths_m.end(), [&](double z) { return view.Sees(z * ray); });
          if (!sees) continue;
          s.view[used] = static_cast<uint8_t>(view.view);
          s.weight[used] = static_cast<float>(1.0 / std::max(view.distance_m, floor_m));
          weight_sum += s.weight[used];
          ++used;
        }
        for (int k = 0; k < used; ++k) s.weight[k] /= weight_sum;
      }
    }
  });
  return out;
}

cv::Rect LargeHoles(const cv::Mat& known, int small_hole_radius_px, cv::Mat* holes) {
  PX_CHECK(known.type() == CV_8U && holes != nullptr) << "LargeHoles: known must be CV_8U";
  *holes = known == 0;
  const cv::Rect crop = cv::boundingRect(*holes);
  if (crop.empty() || small_hole_radius_px <= 0) return crop;
  // A hole is not closed whole by the first pass when some pixel lies farther than the radius
  // from every known pixel (outside the image is not known): tested by erosion first, which is
  // cheap, then SmallHoles on the holes' box.
  const int margin = small_hole_radius_px + 1;
  const cv::Rect region =
      cv::Rect(crop.x - margin, crop.y - margin, crop.width + 2 * margin, crop.height + 2 * margin) &
      cv::Rect(0, 0, known.cols, known.rows);
  cv::Mat deep;
  const int side = 2 * small_hole_radius_px + 1;
  cv::erode((*holes)(region),
            deep,
            cv::getStructuringElement(cv::MORPH_RECT, cv::Size(side, side)),
            cv::Point(-1, -1),
            1,
            cv::BORDER_CONSTANT,
            cv::Scalar(255));
  if (cv::countNonZero(deep) == 0) return cv::Rect();
  (*holes)(region).setTo(0, SmallHoles(known(region), small_hole_radius_px));
  return cv::boundingRect(*holes);
}

OtherViewsReport CoverHolesFromOtherViews(const LayeredScene& scene,
                                          const CameraModel& camera,
                                          const Rigid3& cam_from_world,
                                          const std::vector<ViewSlots>& slots,
                                          RenderQuality quality,
                                          double covered_alpha,
                                          const TextureStretchOptions& stretch,
                                          int small_hole_radius_px,
                                          cv::Mat* known,
                                          FrameComposite* composite) {
  PX_CHECK(known != nullptr && composite != nullptr) << "CoverHolesFromOtherViews needs outputs";
  OtherViewsReport report;
  if (scene.views().size() <= 1) return report;
  report.hole_pixels = static_cast<int>(known->total()) - cv::countNonZero(*known);
  if (report.hole_pixels == 0) return report;
  // Holes the first fill pass closes whole are left to it.
  cv::Mat holes;
  const cv::Rect crop = LargeHoles(*known, small_hole_radius_px, &holes);
  if (crop.empty()) return report;
  report.covered = CoverLargeHolesFromOtherViews(
      scene, camera, cam_from_world, slots, quality, covered_alpha, stretch, holes, crop, known, composite);
  return report;
}

int CoverLargeHolesFromOtherViews(const LayeredScene& scene,
                                  const CameraModel& camera,
                                  const Rigid3& cam_from_world,
                                  const std::vector<ViewSlots>& slots,
                                  RenderQuality quality,
                                  double covered_alpha,
                                  const TextureStretchOptions& stretch,
                                  const cv::Mat& holes,
                                  const cv::Rect& crop,
                                  cv::Mat* known,
                                  FrameComposite* composite) {
  PX_CHECK(known != nullptr && composite != nullptr) << "CoverLargeHolesFromOtherViews needs outputs";
  if (crop.empty() || scene.views().size() <= 1) return 0;
  const std::vector<ViewSlots> crop_slots = OtherViewSlots(scene, camera, cam_from_world, slots, holes, crop);
  if (std::none_of(
          crop_slots.begin(), crop_slots.end(), [](const ViewSlots& s) { return s.view[0] != ViewSlots::kNone; })) {
    return 0;
  }
  // The crop as a camera of its own: the same rays, the principal point moved.
  CameraModel crop_camera = camera;
  crop_camera.width = crop.width;
  crop_camera.height = crop.height;
  crop_camera.cx -= crop.x;
  crop_camera.cy -= crop.y;
  std::vector<FrameView> frame_views;
  SetUpFrame(scene, crop_camera, cam_from_world, crop_slots, stretch, false, &frame_views);
  FrameComposite drawn;
  if (quality == RenderQuality::kOffline) {
    CompositeOffline(scene, frame_views, crop_slots, crop.width, crop.height, &drawn);
  } else {
    CompositePreview(scene, frame_views, crop_slots, crop.width, crop.height, true, &drawn);
  }
  int covered = 0;
  for (int y = 0; y < crop.height; ++y) {
    const uint8_t* hole = holes.ptr<uint8_t>(crop.y + y) + crop.x;
    const float* alpha = drawn.alpha.ptr<float>(y);
    for (int x = 0; x < crop.width; ++x) {
      if (hole[x] == 0 || !(alpha[x] >= covered_alpha)) continue;
      const cv::Point p(crop.x + x, crop.y + y);
      composite->colour.at<cv::Vec3f>(p) = drawn.colour.at<cv::Vec3f>(y, x);
      composite->depth.at<float>(p) = drawn.depth.at<float>(y, x);
      known->at<uint8_t>(p) = 255;
      ++covered;
    }
  }
  return covered;
}

}  // namespace px::render
