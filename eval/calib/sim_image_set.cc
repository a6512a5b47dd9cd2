#include "eval/calib/sim_image_set.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <opencv2/core.hpp>

#include "eval/calib/pose_alignment.h"
#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/handheld_photos.h"
#include "sim/synthetic/ray_caster.h"
#include "sim/synthetic/scene_json.h"

namespace px::sim_calib {
namespace {

constexpr double kFocalPx = 560.0;

Eigen::Quaterniond Turn(double rx_deg, double ry_deg, double rz_deg) {
  const double k = M_PI / 180.0;
  return Eigen::Quaterniond(Eigen::AngleAxisd(rx_deg * k, Eigen::Vector3d::UnitX()) *
                            Eigen::AngleAxisd(ry_deg * k, Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(rz_deg * k, Eigen::Vector3d::UnitZ()));
}

}  // namespace

ImageSet Render(const std::string& scene_name,
                const std::vector<Eigen::Vector3d>& centres_m,
                const std::vector<Eigen::Vector3d>& turns_deg,
                bool known_focal) {
  std::vector<Rigid3> poses;
  for (size_t i = 0; i < centres_m.size(); ++i) {
    const Eigen::Quaterniond rotation = Turn(turns_deg[i].x(), turns_deg[i].y(), turns_deg[i].z());
    poses.emplace_back(rotation, -(rotation * centres_m[i]));
  }
  const CameraModel camera = CameraModel::Pinhole(640, 480, kFocalPx);
  return RenderCameras(scene_name, std::vector<CameraModel>(poses.size(), camera), poses, known_focal);
}

ImageSet RenderCameras(const std::string& scene_name,
                       const std::vector<CameraModel>& cameras,
                       const std::vector<Rigid3>& cam_from_world,
                       bool known_intrinsics) {
  ImageSet set;
  set.camera = cameras.front();
  StatusOr<sim::Scene> scene =
      sim::LoadScene(scene_name.find('/') != std::string::npos ? std::filesystem::path(scene_name)
                                                               : sim::ScenesDir() / (scene_name + ".json"));
  EXPECT_TRUE(scene.ok()) << scene.status().ToString();
  if (!scene.ok()) return set;
  for (size_t i = 0; i < cameras.size(); ++i) {
    StatusOr<sim::RenderedView> view = sim::RenderView(*scene, cameras[i], cam_from_world[i]);
    EXPECT_TRUE(view.ok()) << view.status().ToString();
    if (!view.ok()) return set;
    calib::SfmImage image;
    image.image = view->bgr;
    cv::Mat noise(image.image.size(), CV_16SC3);
    cv::RNG rng(100 + i);
    rng.fill(noise, cv::RNG::NORMAL, 0, 2.0);
    cv::Mat noisy;
    image.image.convertTo(noisy, CV_16SC3);
    noisy += noise;
    noisy.convertTo(image.image, CV_8UC3);
    if (known_intrinsics) {
      image.intrinsics = cameras[i];
      // One camera id per distinct camera (shifted principal points are separate cameras).
      size_t first = 0;
      while (cameras[first].cx != cameras[i].cx || cameras[first].cy != cameras[i].cy ||
             cameras[first].fx != cameras[i].fx) {
        ++first;
      }
      image.camera_id = static_cast<int>(first);
    }
    set.images.push_back(image);
    set.truth.push_back(cam_from_world[i]);
  }
  return set;
}

ImageSet HandHeld(bool known_focal, const std::string& scene) {
  std::vector<Eigen::Vector3d> centres, turns;
  for (const sim::HandHeldPlace& place : sim::HandHeldPlaces()) {
    centres.push_back(place.centre_m);
    turns.push_back(place.turn_deg);
  }
  return Render(scene, centres, turns, known_focal);
}

Figures Compare(const calib::SfmResult& result, const ImageSet& set) {
  std::vector<Rigid3> est;
  std::vector<double> est_f, ref_f;
  for (const calib::SfmView& view : result.views) {
    est.push_back(view.cam_from_world);
    est_f.push_back(view.camera.fx);
    ref_f.push_back(set.camera.fx);
  }
  StatusOr<eval::PoseErrors> errors = eval::ComparePoses(est, set.truth, est_f, ref_f);
  EXPECT_TRUE(errors.ok()) << errors.status().ToString();
  if (!errors.ok()) return {};
  return {eval::PoseErrors::Max(errors->rotation_deg),
          eval::PoseErrors::Max(errors->centre_relative),
          eval::PoseErrors::Max(errors->focal_relative)};
}

void Print(const char* name, const calib::SfmResult& result, const Figures& figures) {
  const calib::SfmReport& r = result.report;
  std::printf(
      "%s: %d/%d registered, %d points, RMS %.3f px, initial pair %d-%d (parallax %.1f px, %.1fx noise), "
      "focal %.1f px (%s), %.0f ms; rotation %.3f deg, centre %.3f baselines, focal %.2f %%\n",
      name,
      r.num_registered,
      r.num_images,
      r.num_points,
      r.rms_px,
      r.initial_image_a,
      r.initial_image_b,
      r.initial_parallax_px,
      r.initial_parallax_ratio,
      result.views[0].camera.fx,
      r.focal_source.c_str(),
      r.total_ms,
      figures.rotation_deg,
      figures.centre,
      100 * figures.focal);
  for (const std::string& warning : r.warnings) std::printf("  warning: %s\n", warning.c_str());
}

}  // namespace px::sim_calib
