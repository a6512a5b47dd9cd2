// The direction stage on real two-view photos with a face (../shared/data stereo_face and the
// hand-held portrait): the product's face detector and PlanCameraPath, as the pipeline runs them
// when two uncalibrated views come in (no trusted depth: a morph, or a flat pan and zoom). Checks
// that a face is found, becomes the subject, stays wholly inside every frame of the clip, and
// that a morph pushes in on it; prints what the stage did ("[figures]" lines).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "device/face_cascades.h"
#include "eval/datasets/image_folder.h"
#include "pipeline/direct/framing.h"
#include "pipeline/direct/morph_framing.h"
#include "pipeline/direct/plan_camera_path.h"
#include "sim/synthetic/data_paths.h"

namespace px {
namespace {

constexpr int kWorkingSidePx = 960;  // reduced size (the morph computes its flow at 640 anyway)

// The smallest distance (pixels) of a face corner from the frame's edges over every frame.
double MinFaceMarginPx(const CameraPath& path, const DirectionReport& report, const Subject& face) {
  double margin = 1e9;
  for (int frame = 0; frame < path.NumFrames(); ++frame) {
    const double t = path.FrameTime(frame);
    if (path.kind == PathKind::kMorph) {
      // The box carried by the morph's flow, in the frame's pixels (the push-in's window).
      CameraPath this_face = path;
      this_face.subjects = {face};
      const cv::Rect2d moved = direct::MorphSubjectsBoxAt(this_face, *report.morph, t);
      const cv::Rect2d window = direct::MorphWindowAt(path, *report.morph, t, DirectOptions{}.framing_margin);
      const double scale = path.width / window.width;
      for (const cv::Point2d corner : {moved.tl(), moved.br()}) {
        const cv::Point2d p = (corner - window.tl()) * scale;
        margin = std::min({margin, p.x, p.y, path.width - 1 - p.x, path.height - 1 - p.y});
      }
    } else {
      const CameraModel camera = path.CameraAt(t);
      const Rigid3 cam_from_world = path.PoseAt(t);
      for (const Eigen::Vector3d& corner : face.corners_in_world) {
        Eigen::Vector2d p;
        if (!camera.Project(cam_from_world * corner, &p)) return -1;
        margin = std::min({margin, p.x(), p.y(), path.width - 1 - p.x(), path.height - 1 - p.y()});
      }
    }
  }
  return margin;
}

void CheckDirection(const std::string& folder) {
  const std::filesystem::path dir = sim::SharedDataDir() / folder;
  if (!std::filesystem::exists(dir)) GTEST_SKIP() << "real data absent: " << dir.string();
  auto detector = device::LoadFaceDetector();
  if (!detector.ok()) GTEST_SKIP() << detector.status().message();
  auto images = eval::LoadImageFolder(dir, kWorkingSidePx);
  ASSERT_TRUE(images.ok()) << images.status().ToString();
  ASSERT_EQ(images->size(), 2u) << dir.string();
  std::vector<View> views;
  for (const eval::FolderImage& image : *images) {
    View view;
    view.id = ViewId{static_cast<int32_t>(views.size())};
    view.image = image.bgr;
    // Without an EXIF focal, a normal lens (focal = the longer side); only 2D moves are planned.
    const double focal_px = image.focal_px > 0 ? image.focal_px : std::max(image.bgr.cols, image.bgr.rows);
    view.camera = CameraModel::Pinhole(image.bgr.cols, image.bgr.rows, focal_px);
    views.push_back(view);
  }
  ASSERT_EQ(views[0].image.size(), views[1].image.size()) << dir.string();
  DirectionContext context;
  context.face_detector = detector->get();
  context.depth_trusted = false;
  context.distrust_reason = "two uncalibrated photos";
  DirectOptions options;
  options.duration_s = 2.0;
  options.fps = 15;
  DirectionReport report;
  auto path = PlanCameraPath(views, {}, options, context, &report);
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  std::printf("[figures] %s: %dx%d; detector %s: %d face(s) found, %d subject(s); %s (%s) over %d frames\n",
              folder.c_str(),
              views[0].image.cols,
              views[0].image.rows,
              report.detector.c_str(),
              report.faces_detected,
              report.num_subjects,
              std::string(PathKindName(path->kind)).c_str(),
              path->move.c_str(),
              path->NumFrames());
  for (const std::string& note : path->notes) std::printf("[figures]   note: %s\n", note.c_str());
  ASSERT_GE(report.faces_detected, 1) << folder << ": no face found";
  ASSERT_FALSE(path->subjects.empty()) << folder << ": the face did not become a subject";
  EXPECT_TRUE(path->kind == PathKind::kMorph || path->kind == PathKind::kPanZoom2d) << PathKindName(path->kind);
  if (path->kind == PathKind::kMorph) {
    ASSERT_NE(report.morph, nullptr);
    EXPECT_EQ(path->move, "morph_push_in") << folder << ": a morph with a face pushes in on it";
  }
  for (const Subject& face : path->subjects) {
    const double margin = MinFaceMarginPx(*path, report, face);
    std::printf("[figures]   face %.0fx%.0f at (%.0f, %.0f): min margin to the frame edge over every frame %.1f px\n",
                face.box_px.width,
                face.box_px.height,
                face.box_px.x,
                face.box_px.y,
                margin);
    EXPECT_GE(margin, 0) << folder << ": the face leaves the frame";
  }
}

TEST(DirectionRealTest, StereoFace) { CheckDirection("stereo_face/ddd_frame31_stereo"); }

TEST(DirectionRealTest, HandHeldPortrait) { CheckDirection("handheld/ddd_seattle_portrait_2views"); }

}  // namespace
}  // namespace px
