// The capture the direction tests plan in: a capture frame equal to the world, 3x3 lenses over
// 10 cm, 640x480 at f 560, the scene 1-1.5 m ahead. Search limits with the default options: 0.6 m
// forwards, 1.5 m back, first step 75 mm, precision 15 mm.
#pragma once

#include "pipeline/core/coverage_report.h"
#include "pipeline/direct/scene_geometry.h"

namespace px::direct {

inline SceneGeometry TestCaptureScene() {
  SceneGeometry scene;
  scene.output = CameraModel::Pinhole(640, 480, 560);
  scene.focal_px = 560;
  scene.box_min = Eigen::Vector2d(-0.05, -0.05);
  scene.box_max = Eigen::Vector2d(0.05, 0.05);
  scene.centroid_in_world = Eigen::Vector3d(0, 0, 1.5);
  scene.centroid_surface_in_world = scene.centroid_in_world;
  scene.median_depth_m = 1.5;
  scene.near_depth_m = 1.0;
  return scene;
}

// The coverage a test's valid-viewpoint region reports for one camera: none missing inside it,
// half the frame a hole outside.
inline CoverageReport ValidityCoverage(const CameraModel& camera, bool valid) {
  CoverageReport report;
  report.width = camera.width;
  report.height = camera.height;
  report.hole_ratio = valid ? 0.0 : 0.5;
  report.hole_score = valid ? 0.0 : 10.0;
  return report;
}

}  // namespace px::direct
