#include "pipeline/depth/plane_scene_test_util.h"

#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

namespace px::depth::testing {

Superpixels BlockSegments(int cols, int rows, int block_px) {
  Superpixels blocks;
  blocks.labels.create(rows, cols, CV_32S);
  const int per_row = (cols + block_px - 1) / block_px;
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) blocks.labels.at<int>(y, x) = (y / block_px) * per_row + x / block_px;
  }
  blocks.count = per_row * ((rows + block_px - 1) / block_px);
  ComputeSuperpixelStats(cv::Mat::zeros(rows, cols, CV_8UC3), &blocks);
  return blocks;
}

cv::Mat RandomTexture(cv::Size size, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat sum(size, CV_32FC3, cv::Scalar::all(0));
  double total_weight = 0;
  for (const double octave_texels : {2.0, 4.0, 8.0, 16.0, 32.0}) {
    const cv::Size coarse(std::max(2, static_cast<int>(size.width / octave_texels)),
                          std::max(2, static_cast<int>(size.height / octave_texels)));
    cv::Mat noise(coarse, CV_32FC3);
    rng.fill(noise, cv::RNG::UNIFORM, -1.0, 1.0);
    cv::Mat up;
    cv::resize(noise, up, size, 0, 0, cv::INTER_CUBIC);
    const double weight = std::sqrt(octave_texels);  // coarser octaves a little stronger, like natural images
    sum += up * weight;
    total_weight += weight;
  }
  cv::Mat texture;
  sum.convertTo(texture, CV_8UC3, 110.0 / total_weight * 2.0, 127.5);
  return texture;
}

cv::Mat RenderPlanes(const CameraModel& camera,
                     const Rigid3& cam_from_world,
                     const std::vector<TexturedPlane>& planes,
                     cv::Mat* depth_m) {
  const cv::Size size(camera.width, camera.height);
  const Rigid3 world_from_cam = cam_from_world.Inverse();
  const Eigen::Matrix3d world_from_cam_rotation = world_from_cam.RotationMatrix();
  const Eigen::Vector3d centre = world_from_cam.translation;
  const Eigen::Matrix3d inverse_k = camera.K().inverse();
  cv::Mat label(size, CV_32S, cv::Scalar(-1));
  cv::Mat depth(size, CV_32F, cv::Scalar(0));
  std::vector<cv::Mat> map_x(planes.size()), map_y(planes.size());
  for (size_t i = 0; i < planes.size(); ++i) {
    map_x[i].create(size, CV_32F);
    map_y[i].create(size, CV_32F);
  }
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      const Eigen::Vector3d ray_in_cam = inverse_k * Eigen::Vector3d(x, y, 1);  // z = 1
      const Eigen::Vector3d ray = world_from_cam_rotation * ray_in_cam;
      double nearest = std::numeric_limits<double>::max();
      for (size_t i = 0; i < planes.size(); ++i) {
        const TexturedPlane& plane = planes[i];
        if (std::abs(ray.z()) < 1e-12) continue;
        const double lambda = (plane.depth_m - centre.z()) / ray.z();  // = z in the camera (ray z = 1)
        if (lambda <= 0) continue;
        const Eigen::Vector3d hit = centre + lambda * ray;
        const bool infinite = plane.extent_m.area() <= 0;
        if (!infinite && !plane.extent_m.contains(cv::Point2d(hit.x(), hit.y()))) continue;
        const double origin_x = infinite ? 0.0 : plane.extent_m.x + plane.extent_m.width / 2;
        const double origin_y = infinite ? 0.0 : plane.extent_m.y + plane.extent_m.height / 2;
        // Texel centres at integers: texel (tw-1)/2 sits on the extent's centre.
        map_x[i].at<float>(y, x) =
            static_cast<float>((hit.x() - origin_x) / plane.metres_per_texel + (plane.texture.cols - 1) / 2.0);
        map_y[i].at<float>(y, x) =
            static_cast<float>((hit.y() - origin_y) / plane.metres_per_texel + (plane.texture.rows - 1) / 2.0);
        if (lambda < nearest) {
          nearest = lambda;
          label.at<int>(y, x) = static_cast<int>(i);
          depth.at<float>(y, x) = static_cast<float>(lambda);
        }
      }
    }
  }
  cv::Mat image(size, CV_8UC3, cv::Scalar(0, 0, 0));
  for (size_t i = 0; i < planes.size(); ++i) {
    cv::Mat sampled;
    cv::remap(planes[i].texture, sampled, map_x[i], map_y[i], cv::INTER_LINEAR, cv::BORDER_REFLECT);
    sampled.copyTo(image, label == static_cast<int>(i));
  }
  if (depth_m != nullptr) *depth_m = depth;
  return image;
}

std::vector<View> RenderViews(const std::vector<Rigid3>& cams_from_world,
                              const CameraModel& camera,
                              const std::vector<TexturedPlane>& planes,
                              std::vector<cv::Mat>* true_depth_m) {
  std::vector<View> views;
  if (true_depth_m != nullptr) true_depth_m->clear();
  for (const Rigid3& cam_from_world : cams_from_world) {
    View view;
    view.id = ViewId{static_cast<int>(views.size())};
    view.camera = camera;
    view.cam_from_world = cam_from_world;
    cv::Mat depth;
    view.image = RenderPlanes(camera, view.cam_from_world, planes, &depth);
    if (true_depth_m != nullptr) true_depth_m->push_back(depth);
    views.push_back(std::move(view));
  }
  return views;
}

std::vector<Rigid3> GridRigPoses(int rows, int cols, double baseline_m) {
  std::vector<Rigid3> poses;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const Eigen::Vector3d centre((c - (cols - 1) / 2.0) * baseline_m, (r - (rows - 1) / 2.0) * baseline_m, 0);
      poses.emplace_back(Eigen::Quaterniond::Identity(), -centre);
    }
  }
  return poses;
}

std::vector<View> RenderGridRig(int rows,
                                int cols,
                                double baseline_m,
                                const CameraModel& camera,
                                const std::vector<TexturedPlane>& planes,
                                std::vector<cv::Mat>* true_depth_m) {
  return RenderViews(GridRigPoses(rows, cols, baseline_m), camera, planes, true_depth_m);
}

}  // namespace px::depth::testing
