// Test-only: an analytic scene of two textured planes, rendered exactly by ray casting, for the
// render tests and benchmark. A background plane at z = kBackgroundZ and a foreground rectangle
// at z = kForegroundZ (world = rig frame: x right, y down, z forward); smooth sinusoidal textures
// (periods of ~15 px at the test focal lengths) so bilinear resampling is nearly exact.
#pragma once

#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/view.h"

namespace px::render::testing {

struct PlaneScene {
  double background_z = 3.0;
  double foreground_z = 1.0;
  cv::Rect2d foreground_xy = cv::Rect2d(-0.2, -0.12, 0.3, 0.24);  // metres, at foreground_z

  // Distance t along centre + t * dir to the first surface, and whether it is the foreground.
  bool Cast(const Eigen::Vector3d& centre, const Eigen::Vector3d& dir, Eigen::Vector3d* point, bool* foreground) const {
    if (dir.z() <= 1e-12) return false;
    const double t_fg = (foreground_z - centre.z()) / dir.z();
    if (t_fg > 0) {
      const Eigen::Vector3d p = centre + t_fg * dir;
      if (p.x() >= foreground_xy.x && p.x() <= foreground_xy.x + foreground_xy.width && p.y() >= foreground_xy.y &&
          p.y() <= foreground_xy.y + foreground_xy.height) {
        *point = p;
        *foreground = true;
        return true;
      }
    }
    const double t_bg = (background_z - centre.z()) / dir.z();
    if (t_bg <= 0) return false;
    *point = centre + t_bg * dir;
    *foreground = false;
    return true;
  }

  // True when the straight segment from `centre` to the surface point `p` is not blocked.
  bool Visible(const Eigen::Vector3d& centre, const Eigen::Vector3d& p) const {
    Eigen::Vector3d hit;
    bool foreground = false;
    if (!Cast(centre, (p - centre).normalized(), &hit, &foreground)) return false;
    return (hit - p).norm() < 1e-6;
  }

  static cv::Vec3b Colour(const Eigen::Vector3d& p, bool foreground) {
    constexpr double kTwoPi = 6.283185307179586;
    const double x = p.x(), y = p.y();
    double b, g, r;
    if (foreground) {
      b = 90 + 60 * std::sin(kTwoPi * x / 0.05) * std::cos(kTwoPi * y / 0.06);
      g = 170 + 50 * std::sin(kTwoPi * y / 0.045);
      r = 70 + 45 * std::cos(kTwoPi * x / 0.07);
    } else {
      b = 128 + 50 * std::sin(kTwoPi * x / 0.16);
      g = 110 + 50 * std::sin(kTwoPi * y / 0.13);
      r = 140 + 40 * std::sin(kTwoPi * (x + y) / 0.2);
    }
    return cv::Vec3b(cv::saturate_cast<uint8_t>(b), cv::saturate_cast<uint8_t>(g), cv::saturate_cast<uint8_t>(r));
  }

  // Renders the exact image and depth (z in the camera) seen by a pinhole camera.
  void Render(const CameraModel& camera, const Rigid3& cam_from_world, cv::Mat* bgr, cv::Mat* depth_m) const {
    bgr->create(camera.height, camera.width, CV_8UC3);
    depth_m->create(camera.height, camera.width, CV_32F);
    const Eigen::Matrix3d world_from_cam = cam_from_world.RotationMatrix().transpose();
    const Eigen::Vector3d centre = CameraCentre(cam_from_world);
    for (int v = 0; v < camera.height; ++v) {
      for (int u = 0; u < camera.width; ++u) {
        const Eigen::Vector3d ray_in_cam((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
        Eigen::Vector3d p;
        bool foreground = false;
        if (!Cast(centre, world_from_cam * ray_in_cam, &p, &foreground)) {
          bgr->at<cv::Vec3b>(v, u) = cv::Vec3b(0, 0, 0);
          depth_m->at<float>(v, u) = 0;
          continue;
        }
        bgr->at<cv::Vec3b>(v, u) = Colour(p, foreground);
        depth_m->at<float>(v, u) = static_cast<float>((cam_from_world * p).z());
      }
    }
  }
};

// A rows x cols lattice rig in the rig frame (lens centres baseline_m apart, all looking down +z)
// seeing `scene`, with exact depth maps of confidence 1.
inline void MakeLatticeViews(const PlaneScene& scene,
                             int rows,
                             int cols,
                             double baseline_m,
                             const CameraModel& camera,
                             std::vector<View>* views,
                             std::vector<DepthMap>* depths) {
  views->clear();
  depths->clear();
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      View view;
      view.id.value = r * cols + c;
      view.camera = camera;
      const Eigen::Vector3d centre((c - (cols - 1) / 2.0) * baseline_m, (r - (rows - 1) / 2.0) * baseline_m, 0);
      view.cam_from_world = Rigid3(Eigen::Quaterniond::Identity(), -centre);
      DepthMap depth;
      depth.id = view.id;
      scene.Render(camera, view.cam_from_world, &view.image, &depth.depth_m);
      depth.confidence = cv::Mat(camera.height, camera.width, CV_32F, cv::Scalar(1));
      views->push_back(view);
      depths->push_back(depth);
    }
  }
}

}  // namespace px::render::testing
