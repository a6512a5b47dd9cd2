// The direction stage (paper section 4) on simulated Pop9 shots with 0, 1 and 2 faces (issue 6,
// item 10): the taxonomy row the faces call for, H(V) under the threshold at every frame of the
// chosen path (rendered for real at the output size), every face wholly inside every frame, the
// dolly zoom holding the subject's size, and more parallax than the straight path between the
// two nearest input views. Depth is the simulator's truth, so the checks measure direction alone.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "device/face_cascades.h"
#include "pipeline/direct/aperture_search.h"
#include "pipeline/direct/framing.h"
#include "pipeline/direct/parallax_measure.h"
#include "pipeline/direct/plan_camera_path.h"
#include "pipeline/direct/shot_file.h"
#include "pipeline/direct/subjects.h"
#include "pipeline/direct/taxonomy.h"
#include "sim/synthetic/data_paths.h"
#include "tests/e2e/direction_shot.h"

namespace px {
namespace {

using Shot = e2e::DirectionShot;

std::unique_ptr<Shot> MakeShot(const std::string& scene) {
  StatusOr<std::unique_ptr<Shot>> shot = e2e::MakeDirectionShot(scene, 0.5);
  EXPECT_TRUE(shot.ok()) << shot.status().ToString();
  return shot.ok() ? std::move(shot).value() : nullptr;
}

struct Planned {
  CameraPath path;
  DirectionReport report;
};

Planned Plan(Shot* shot,
             const direct::FaceDetector* detector,
             const std::string& move,
             const std::string& effect = "none") {
  DirectOptions options;
  options.fps = 10;
  options.duration_s = 1;  // 10 frames
  options.move = move;
  options.effect = effect;
  DirectionContext context;
  context.face_detector = detector;
  context.coverage = shot->Coverage();
  context.coverage_concurrent = true;  // CpuSceneRenderer::Coverage
  Planned planned;
  StatusOr<CameraPath> path = PlanCameraPath(shot->views, shot->depths, options, context, &planned.report);
  EXPECT_TRUE(path.ok()) << path.status().ToString();
  if (path.ok()) planned.path = std::move(path).value();
  return planned;
}

// The checks every automatic path must pass; prints its figures. subjects_detected: the faces
// found, when the move frames fewer of them than that (-1: as many as it frames).
void CheckPath(Shot* shot, const Planned& planned, int subjects_expected, int subjects_detected = -1) {
  const CameraPath& path = planned.path;
  std::string notes;
  for (const std::string& note : path.notes) notes += "\n  " + note;
  EXPECT_FALSE(planned.report.fell_back) << path.reason << notes;
  ASSERT_EQ(path.kind, PathKind::kNovelView) << path.reason << notes;
  EXPECT_EQ(planned.report.num_subjects, subjects_detected < 0 ? subjects_expected : subjects_detected)
      << planned.report.detector;
  ASSERT_EQ(static_cast<int>(path.subjects.size()), subjects_expected);

  // H(V) at every frame, at the output size.
  double worst_hole_score = 0;
  for (int i = 0; i < path.NumFrames(); ++i) {
    const double t = path.FrameTime(i);
    StatusOr<CoverageReport> coverage = shot->renderer->Coverage(path.CameraAt(t), path.PoseAt(t));
    ASSERT_TRUE(coverage.ok()) << coverage.status().ToString();
    EXPECT_LT(coverage->hole_score, 2.0) << "frame " << i;
    worst_hole_score = std::max(worst_hole_score, coverage->hole_score);
    EXPECT_TRUE(direct::SubjectsInside(path.subjects, path.CameraAt(t), path.PoseAt(t), 0.0)) << "frame " << i;
  }

  // Parallax against the straight path between the centre view and its nearest neighbour.
  const direct::SceneSamples samples = direct::SceneSamples::FromDepths(shot->views, shot->depths);
  const View& centre = shot->views[direct::CentreViewIndex(shot->views)];
  const View* nearest = nullptr;
  for (const View& view : shot->views) {
    if (&view == &centre) continue;
    const double d = (CameraCentre(view.cam_from_world) - CameraCentre(centre.cam_from_world)).norm();
    if (nearest == nullptr ||
        d < (CameraCentre(nearest->cam_from_world) - CameraCentre(centre.cam_from_world)).norm()) {
      nearest = &view;
    }
  }
  const CameraModel small = centre.camera.WithoutDistortion().Scaled(0.25);
  const double input_parallax =
      direct::ParallaxScore(samples, small, centre.cam_from_world, small, nearest->cam_from_world);
  const double chosen_parallax = direct::ParallaxScore(
      samples, path.CameraAt(0).Scaled(0.25), path.PoseAt(0), path.CameraAt(1).Scaled(0.25), path.PoseAt(1));
  EXPECT_GE(chosen_parallax, input_parallax);
  std::printf(
      "[figures] %s (%d subjects): max H(V) %.3f over %d frames; parallax %.4f vs %.4f between the nearest "
      "views; %d coverage probes in %.0f ms, subjects %.0f ms, %.0f ms in all\n",
      path.move.c_str(),
      subjects_expected,
      worst_hole_score,
      path.NumFrames(),
      chosen_parallax,
      input_parallax,
      planned.report.coverage_probes,
      planned.report.coverage_ms,
      planned.report.subjects_ms,
      planned.report.total_ms);
}

// Every corner of the aperture's box around `key` is a valid viewpoint at the output size (4.3).
void ExpectApertureCornersValid(
    Shot* shot, const CameraPath& path, const CameraKeyframe& key, double aperture_m, const std::string& what) {
  direct::Framing end;
  end.centre_in_world = key.centre_in_world;
  end.cam_from_world = key.CamFromWorld();
  end.focal_px = key.focal_px;
  for (const direct::Framing& corner : direct::ApertureCorners(end, aperture_m)) {
    StatusOr<CoverageReport> coverage = shot->renderer->Coverage(path.CameraAt(key.t), corner.cam_from_world);
    ASSERT_TRUE(coverage.ok()) << coverage.status().ToString();
    EXPECT_LT(coverage->hole_score, 2.0) << "aperture corner of " << what;
  }
}

class DirectionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto detector = device::LoadFaceDetector();
    if (!detector.ok()) GTEST_SKIP() << detector.status().message();
    detector_ = *detector;
  }
  // The face scenes are textured from real photos in ../shared/data (faces_dlib_pascalvoc).
  void NeedFacePhotos() {
    if (!std::filesystem::exists(sim::SharedDataDir() / "faces_dlib_pascalvoc")) {
      GTEST_SKIP() << "face photos absent: " << (sim::SharedDataDir() / "faces_dlib_pascalvoc").string();
    }
  }
  std::shared_ptr<const direct::FaceDetector> detector_;
};

// How far above the image centre the face's centre lies, as a fraction of the frame height, at the
// path's time t (paper 4.2.3: an end aimed at a face leaves it slightly above centre).
double FaceAboveCentreFraction(const CameraPath& path, const Subject& face, double t) {
  const CameraModel camera = path.CameraAt(t);
  Eigen::Vector2d pixel;
  if (!camera.Project(path.PoseAt(t) * face.CentreInWorld(), &pixel)) return -1;
  return (camera.cy - pixel.y()) / camera.height;
}

// The end of a one-face move that is aimed at the face has it slightly above centre: its centre is
// above the principal point, and the image centre still falls on the face's lower half (the face is
// raised by less than half its own height, whatever the zoom).
void ExpectFaceSlightlyAboveCentre(const CameraPath& path, const Subject& face, double t) {
  const double above = FaceAboveCentreFraction(path, face, t);
  const double face_height =
      direct::ProjectedHeightPx(face, path.CameraAt(t), path.PoseAt(t)) / path.CameraAt(t).height;
  EXPECT_GT(above, 0.0) << path.move << " at t " << t << ": the face is not above centre";
  EXPECT_LT(above, 0.5 * face_height) << path.move << " at t " << t << ": the face is raised by over half its height";
  std::printf("[figures] %s at t %.0f: face centre %.1f %% of the frame height above centre (face %.1f %% high)\n",
              path.move.c_str(),
              t,
              100 * above,
              100 * face_height);
}

// A dolly zoom keeps its subject's projected height: each frame's within 3 % of the first's.
// Returns the largest change (a fraction).
double WorstDollyZoomSizeChange(const CameraPath& path, const Subject& face) {
  const double start_px = direct::ProjectedHeightPx(face, path.CameraAt(0), path.PoseAt(0));
  EXPECT_GT(start_px, 0);
  double worst = 0;
  for (int i = 0; i < path.NumFrames(); ++i) {
    const double t = path.FrameTime(i);
    const double px = direct::ProjectedHeightPx(face, path.CameraAt(t), path.PoseAt(t));
    worst = std::max(worst, std::abs(px / start_px - 1));
    EXPECT_NEAR(px / start_px, 1.0, 0.03) << "frame " << i;
  }
  return worst;
}

TEST_F(DirectionTest, NoFacesTakesAnEstablishingMove) {
  std::unique_ptr<Shot> shot = MakeShot("still_life");
  ASSERT_NE(shot, nullptr);
  const Planned planned = Plan(shot.get(), detector_.get(), "auto");
  ASSERT_NO_FATAL_FAILURE(CheckPath(shot.get(), planned, 0));
  EXPECT_EQ(direct::SubjectsNeeded(direct::ParseMove(planned.path.move).value()), 0) << planned.path.move;
}

TEST_F(DirectionTest, OneFaceTakesARowOneMoveAndTheDollyZoomHoldsItsSize) {
  NeedFacePhotos();
  if (IsSkipped()) return;
  std::unique_ptr<Shot> shot = MakeShot("one_face");
  ASSERT_NE(shot, nullptr);
  const Planned planned = Plan(shot.get(), detector_.get(), "auto");
  ASSERT_NO_FATAL_FAILURE(CheckPath(shot.get(), planned, 1));
  EXPECT_EQ(direct::SubjectsNeeded(direct::ParseMove(planned.path.move).value()), 1) << planned.path.move;
  // Dolly in ends on the face, dolly out starts on it, a dolly zoom is on it throughout.
  const bool in = planned.path.move == "dolly_in";
  ExpectFaceSlightlyAboveCentre(planned.path, planned.path.subjects.front(), in ? 1.0 : 0.0);

  const Planned zoom = Plan(shot.get(), detector_.get(), "dolly_zoom");
  ASSERT_NO_FATAL_FAILURE(CheckPath(shot.get(), zoom, 1));
  ASSERT_NE(zoom.path.move.find("dolly_zoom"), std::string::npos) << zoom.path.reason;
  const Subject& face = zoom.path.subjects.front();
  ExpectFaceSlightlyAboveCentre(zoom.path, face, 0.0);
  ExpectFaceSlightlyAboveCentre(zoom.path, face, 1.0);
  const double worst = WorstDollyZoomSizeChange(zoom.path, face);
  const double travel_m = (CameraCentre(zoom.path.PoseAt(0)) - CameraCentre(zoom.path.PoseAt(1))).norm();
  EXPECT_GT(travel_m, 0.01) << "a dolly zoom that does not move";
  std::printf("[figures] dolly zoom: subject height within %.2f%% over %d frames, %.0f mm of travel\n",
              100 * worst,
              zoom.path.NumFrames(),
              1000 * travel_m);
}

// The product's size (9 views of 640x480): H(V) is not scale-free (a hole twice as many pixels
// wide weighs 8 times as much), so the valid region is narrower than at 320x240; the dolly in
// must still hold on the one-face scene, every frame valid at 640x480 and the face inside.
// Structure from motion's scale is a guess: the same face, its depth at a third of the truth,
// is 5 cm wide in those units. With a metric rig the size check drops it (a face-like texture);
// without one the face is kept, with a note, and becomes the subject.
TEST_F(DirectionTest, AFaceIsNotJudgedByAMetricSizeWhenTheScaleIsNotMetric) {
  NeedFacePhotos();
  if (IsSkipped()) return;
  std::unique_ptr<Shot> shot = MakeShot("one_face");
  ASSERT_NE(shot, nullptr);
  std::vector<DepthMap> shrunk = shot->depths;
  for (DepthMap& depth : shrunk) depth.depth_m = depth.depth_m * (1.0 / 3);
  const int centre = direct::CentreViewIndex(shot->views);
  DirectOptions options;
  for (const bool metric : {true, false}) {
    StatusOr<direct::SubjectSearch> found =
        direct::FindSubjects(shot->views, shrunk, centre, detector_.get(), options, nullptr, metric);
    ASSERT_TRUE(found.ok()) << found.status().ToString();
    ASSERT_GE(found->detections, 1);
    std::string notes;
    for (const std::string& note : found->notes) notes += note + "; ";
    std::printf("[figures] metric scale %d: %d face(s), %zu subject(s): %s\n",
                metric,
                found->detections,
                found->subjects.size(),
                notes.c_str());
    EXPECT_EQ(found->subjects.empty(), metric) << notes;
    EXPECT_NE(notes.find(metric ? "m wide at" : "not metric"), std::string::npos) << notes;
  }
}

TEST_F(DirectionTest, OneFaceDollyInHoldsAtTheProductSize) {
  NeedFacePhotos();
  if (IsSkipped()) return;
  StatusOr<std::unique_ptr<Shot>> shot = e2e::MakeDirectionShot("one_face", 1.0);
  ASSERT_TRUE(shot.ok()) << shot.status().ToString();
  ASSERT_EQ((*shot)->views.front().camera.width, 640);
  const Planned planned = Plan(shot->get(), detector_.get(), "dolly_in");
  ASSERT_NO_FATAL_FAILURE(CheckPath(shot->get(), planned, 1));
  EXPECT_EQ(planned.path.move, "dolly_in") << planned.path.reason;
  ExpectFaceSlightlyAboveCentre(planned.path, planned.path.subjects.front(), 1.0);
}

TEST_F(DirectionTest, TwoFacesDollyBetweenThem) {
  NeedFacePhotos();
  if (IsSkipped()) return;
  std::unique_ptr<Shot> shot = MakeShot("two_faces");
  ASSERT_NE(shot, nullptr);
  // The faces sit 6 and 5 degrees either side of the axis at 1.0 and 1.7 m: the rig's viewpoints
  // can dolly from one to the other with both in every frame.
  const Planned planned = Plan(shot.get(), detector_.get(), "auto");
  EXPECT_EQ(planned.path.move, "dolly") << planned.path.reason;
  EXPECT_EQ(direct::SubjectsNeeded(direct::ParseMove(planned.path.move).value()), 2) << planned.path.move;
  ASSERT_NO_FATAL_FAILURE(CheckPath(shot.get(), planned, 2));
}

// A dolly zoom on a face off the axis: aimed at it, every viewpoint turns past the rays the lenses
// saw, so the camera looks along the capture axis instead, as a dolly zoom on a track does. The
// face then keeps its size and its place in the frame while the background moves.
TEST_F(DirectionTest, TwoFacesDollyZoomOnAnOffAxisFaceLooksAlongTheAxis) {
  NeedFacePhotos();
  if (IsSkipped()) return;
  std::unique_ptr<Shot> shot = MakeShot("two_faces");
  ASSERT_NE(shot, nullptr);
  const Planned zoom = Plan(shot.get(), detector_.get(), "dolly_zoom");
  ASSERT_NO_FATAL_FAILURE(CheckPath(shot.get(), zoom, 1, 2));
  ASSERT_NE(zoom.path.move.find("dolly_zoom"), std::string::npos) << zoom.path.reason;
  EXPECT_NE(zoom.path.reason.find("looking along the axis"), std::string::npos) << zoom.path.reason;
  const Subject& face = zoom.path.subjects.front();
  const CameraModel camera0 = zoom.path.CameraAt(0);
  Eigen::Vector2d start_pixel;
  ASSERT_TRUE(camera0.Project(zoom.path.PoseAt(0) * face.CentreInWorld(), &start_pixel));
  EXPECT_GT((start_pixel - Eigen::Vector2d(camera0.cx, camera0.cy)).norm(), 0.05 * camera0.width)
      << "the face is on the axis: nothing off-axis is tested";
  const double worst_size = WorstDollyZoomSizeChange(zoom.path, face);
  double worst_shift_px = 0;
  for (int i = 0; i < zoom.path.NumFrames(); ++i) {
    const double t = zoom.path.FrameTime(i);
    const CameraModel camera = zoom.path.CameraAt(t);
    Eigen::Vector2d pixel;
    ASSERT_TRUE(camera.Project(zoom.path.PoseAt(t) * face.CentreInWorld(), &pixel));
    worst_shift_px = std::max(worst_shift_px, (pixel - start_pixel).norm());
    EXPECT_LT((pixel - start_pixel).norm(), 0.02 * camera.width) << "frame " << i;
    EXPECT_LT(RotationErrorDeg(zoom.path.PoseAt(t), zoom.path.PoseAt(0)), 0.01) << "frame " << i;
  }
  const double travel_m = (CameraCentre(zoom.path.PoseAt(0)) - CameraCentre(zoom.path.PoseAt(1))).norm();
  EXPECT_GT(travel_m, 0.05) << "a dolly zoom that hardly moves";
  std::printf(
      "[figures] dolly zoom on the off-axis face: height within %.2f%%, place within %.1f px over %d frames, "
      "%.0f mm of travel\n",
      100 * worst_size,
      worst_shift_px,
      zoom.path.NumFrames(),
      1000 * travel_m);
}

// Effects (4.3) on the two-subject dolly: the focus pull's aperture keeps both ends valid at the
// four corners of the aperture's box (rendered coverage at the output size), and the focus goes
// from the first subject's depth to the second's.
TEST_F(DirectionTest, TwoFacesDollyPullsFocusWithTheLargestValidAperture) {
  NeedFacePhotos();
  if (IsSkipped()) return;
  std::unique_ptr<Shot> shot = MakeShot("two_faces");
  ASSERT_NE(shot, nullptr);
  const Planned planned = Plan(shot.get(), detector_.get(), "dolly", "focus_pull");
  const CameraPath& path = planned.path;
  ASSERT_EQ(path.move, "dolly") << path.reason;
  ASSERT_EQ(path.effect, "focus_pull") << path.reason;
  ASSERT_EQ(path.subjects.size(), 2u);
  const double aperture = path.keyframes.front().aperture_m;
  EXPECT_GT(aperture, 1e-4);
  EXPECT_LE(aperture, DirectOptions{}.max_aperture_m);
  for (const CameraKeyframe* key : {&path.keyframes.front(), &path.keyframes.back()}) {
    EXPECT_DOUBLE_EQ(key->aperture_m, aperture);
    ExpectApertureCornersValid(shot.get(), path, *key, aperture, "the end at t = " + std::to_string(key->t));
  }
  EXPECT_NEAR(path.keyframes.front().focus_depth_m,
              direct::SubjectDepthIn(path.subjects[0], path.keyframes.front().CamFromWorld()),
              1e-6);
  EXPECT_NEAR(path.keyframes.back().focus_depth_m,
              direct::SubjectDepthIn(path.subjects[1], path.keyframes.back().CamFromWorld()),
              1e-6);
  std::printf("[figures] dolly with focus pull: aperture %.1f mm; focus %.2f m -> %.2f m\n",
              1000 * aperture,
              path.keyframes.front().focus_depth_m,
              path.keyframes.back().focus_depth_m);
}

// A depth-of-field change (4.3): the two-subject dolly opens from a pinhole to the largest aperture
// that keeps its end valid at the four corners of the aperture's box, focused on the subject it
// ends on (the pinhole end constrains no aperture).
TEST_F(DirectionTest, TwoFacesDollyRampsTheApertureFromPinholeToTheLargestValid) {
  NeedFacePhotos();
  if (IsSkipped()) return;
  std::unique_ptr<Shot> shot = MakeShot("two_faces");
  ASSERT_NE(shot, nullptr);
  const Planned planned = Plan(shot.get(), detector_.get(), "dolly", "dof_change");
  const CameraPath& path = planned.path;
  ASSERT_EQ(path.move, "dolly") << path.reason;
  ASSERT_EQ(path.subjects.size(), 2u);
  ASSERT_EQ(path.effect, "dof_change") << path.reason;
  const CameraKeyframe& end = path.keyframes.back();
  const double aperture = end.aperture_m;
  EXPECT_GT(aperture, 1e-4);
  EXPECT_LE(aperture, DirectOptions{}.max_aperture_m);
  EXPECT_DOUBLE_EQ(path.keyframes.front().aperture_m, 0.0) << "the ramp starts from a pinhole";
  double previous = -1;
  for (int i = 0; i < path.NumFrames(); ++i) {
    const VirtualCamera frame = path.FrameAt(path.FrameTime(i));
    EXPECT_GE(frame.aperture_m, previous) << "frame " << i << ": the aperture closes again";
    previous = frame.aperture_m;
    if (frame.aperture_m > 0) {
      EXPECT_NEAR(frame.focus_depth_m, direct::SubjectDepthIn(path.subjects[1], frame.cam_from_world), 0.05)
          << "frame " << i << ": not focused on the subject the dolly ends on";
    }
  }
  EXPECT_NEAR(previous, aperture, 1e-9);
  ExpectApertureCornersValid(shot.get(), path, end, aperture, "the end");
  std::printf("[figures] dolly with a depth-of-field change: aperture 0 -> %.1f mm over %d frames\n",
              1000 * aperture,
              path.NumFrames());
}

// The one-face dolly in with a depth-of-field change: the aperture opens towards the close-up,
// and every aperture corner of the close-up is valid at the output size.
TEST_F(DirectionTest, OneFaceDollyInOpensTheApertureOnTheCloseUp) {
  NeedFacePhotos();
  if (IsSkipped()) return;
  std::unique_ptr<Shot> shot = MakeShot("one_face");
  ASSERT_NE(shot, nullptr);
  const Planned planned = Plan(shot.get(), detector_.get(), "dolly_in", "dof_change");
  const CameraPath& path = planned.path;
  ASSERT_EQ(path.move, "dolly_in") << path.reason;
  ASSERT_EQ(path.effect, "dof_change") << path.reason;
  const CameraKeyframe& end = path.keyframes.back();
  EXPECT_GT(end.aperture_m, 1e-4);
  EXPECT_DOUBLE_EQ(path.keyframes.front().aperture_m, 0.0);
  ExpectApertureCornersValid(shot.get(), path, end, end.aperture_m, "the close-up");
  std::printf("[figures] one-face dolly in with a depth-of-field change: aperture 0 -> %.1f mm\n",
              1000 * end.aperture_m);
}

// A saturation layer on the subject (4.3), keyframed from unchanged to its target.
TEST_F(DirectionTest, OneFaceDollyInCarriesAKeyframedSaturationLayer) {
  NeedFacePhotos();
  if (IsSkipped()) return;
  std::unique_ptr<Shot> shot = MakeShot("one_face");
  ASSERT_NE(shot, nullptr);
  const Planned planned = Plan(shot.get(), detector_.get(), "dolly_in", "saturation");
  const CameraPath& path = planned.path;
  ASSERT_EQ(path.effect, "saturation") << path.reason;
  ASSERT_EQ(path.keyframes.front().effects.size(), 1u);
  ASSERT_EQ(path.keyframes.back().effects.size(), 1u);
  EXPECT_EQ(path.keyframes.front().effects[0].kind, ColorEffectKind::kSaturation);
  EXPECT_DOUBLE_EQ(path.keyframes.front().effects[0].amount, 1.0);
  EXPECT_GT(path.keyframes.back().effects[0].amount, 1.2);
  // The layer's box holds the face.
  const ColorEffect& layer = path.keyframes.back().effects[0];
  for (const Eigen::Vector3d& corner : path.subjects.front().corners_in_world) {
    EXPECT_TRUE((corner.array() >= layer.region_min_in_world.array()).all() &&
                (corner.array() <= layer.region_max_in_world.array()).all());
  }
}

// Authored shots (4.4): a taxonomy move on a region the user marks, chained with authored
// keyframes; the shot written from the planned path replays the same path.
TEST_F(DirectionTest, AShotChainsAMoveOnAUserRegionWithAuthoredKeyframesAndReplays) {
  std::unique_ptr<Shot> shot = MakeShot("one_face");
  ASSERT_NE(shot, nullptr);
  // The face in the centre view (320x240, f = 280): about 0.17 m wide at 1.2 m, 0.05 m above the axis.
  StatusOr<direct::Shot> authored = direct::ShotFromJson(nlohmann::json::parse(R"({
    "duration_s": 2,
    "segments": [
      {"move": "dolly_in", "effect": "none", "subjects": [{"box_px": [140, 90, 40, 40]}]},
      {"keyframes": [
         {"t": 0, "position_m": [0, 0, 0], "look_at_m": [0, 0, 1.2], "focal_scale": 1.5},
         {"t": 0.5, "position_m": [0.02, 0.01, 0.05], "look_at_m": [0, 0, 1.2], "focal_scale": 1.4},
         {"t": 1, "position_m": [0.03, 0, 0.08], "look_at_m": [0, 0, 1.2], "focal_scale": 1.3}]}
    ]})"));
  ASSERT_TRUE(authored.ok()) << authored.status().ToString();
  DirectOptions options;
  options.fps = 10;
  DirectionContext context;
  context.coverage = shot->Coverage();
  context.coverage_concurrent = true;  // CpuSceneRenderer::Coverage
  context.shot = &*authored;
  DirectionReport report;
  StatusOr<CameraPath> path = PlanCameraPath(shot->views, shot->depths, options, context, &report);
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  EXPECT_EQ(path->kind, PathKind::kNovelView);
  std::string notes;
  for (const std::string& note : path->notes) notes += "\n  " + note;
  EXPECT_NE(path->reason.find("authored shot: dolly_in"), std::string::npos) << path->reason << notes;
  EXPECT_NE(path->reason.find(", then 3 keyframes"), std::string::npos) << path->reason;
  ASSERT_FALSE(path->subjects.empty());
  EXPECT_EQ(path->subjects.front().source, "user");
  EXPECT_EQ(path->NumFrames(), 20);
  // The authored segment's last key is where the clip ends.
  EXPECT_LT((CameraCentre(path->PoseAt(1)) - Eigen::Vector3d(0.03, 0, 0.08)).norm(), 1e-6);

  // Replay the shot written from this path: the same cameras at every frame.
  const direct::Shot written = direct::ShotFromPath(*path);
  StatusOr<direct::Shot> reread = direct::ShotFromJson(nlohmann::json::parse(direct::ShotToJson(written).dump()));
  ASSERT_TRUE(reread.ok()) << reread.status().ToString();
  context.shot = &*reread;
  StatusOr<CameraPath> replayed = PlanCameraPath(shot->views, shot->depths, options, context);
  ASSERT_TRUE(replayed.ok()) << replayed.status().ToString();
  ASSERT_EQ(replayed->NumFrames(), path->NumFrames());
  double worst_m = 0;
  for (int i = 0; i < path->NumFrames(); ++i) {
    const double t = path->FrameTime(i);
    worst_m = std::max(worst_m, (CameraCentre(replayed->PoseAt(t)) - CameraCentre(path->PoseAt(t))).norm());
    EXPECT_LT(replayed->PoseAt(t).rotation.angularDistance(path->PoseAt(t).rotation), 1e-6) << t;
    EXPECT_NEAR(replayed->FocalAt(t), path->FocalAt(t), 1e-6) << t;
  }
  EXPECT_LT(worst_m, 1e-6);
  std::printf("[figures] shot: %s; replayed within %.2g m\n", path->reason.c_str(), worst_m);
}

}  // namespace
}  // namespace px
