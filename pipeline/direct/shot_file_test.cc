// Shot files (SHOT_FORMAT.md): parsing, the documented errors naming the field, Catmull-Rom
// keyframes, and the written shot of a path re-rendering the same path (round trip).
#include "pipeline/direct/shot_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

namespace px::direct {
namespace {

nlohmann::json TwoSegmentShot() {
  return nlohmann::json::parse(R"({
    "format": "parallax-shot", "version": 1, "duration_s": 8, "_note": "ignored",
    "segments": [
      {"move": "dolly_in", "effect": "dof_change", "subjects": [{"box_px": [250, 120, 90, 90]}], "duration_s": 5},
      {"keyframes": [
         {"t": 0, "position_m": [0, 0, 0.10], "look_at_m": [0, 0, 1.5], "focal_scale": 1.5},
         {"t": 0.5, "position_m": [0.02, 0, 0.05], "look_at_m": [0, 0, 1.5], "focal_scale": 1.2, "aperture_m": 0.01,
          "focus_at_m": [0, 0, 1.5]},
         {"t": 1, "position_m": [0.03, 0, -0.10], "look_at_m": [0, 0, 1.5], "focal_scale": 1.0}]}
    ]})");
}

TEST(ShotFileTest, ParsesTheDocumentedExample) {
  StatusOr<Shot> shot = ShotFromJson(TwoSegmentShot());
  ASSERT_TRUE(shot.ok()) << shot.status().ToString();
  ASSERT_EQ(shot->segments.size(), 2u);
  EXPECT_EQ(shot->segments[0].move, "dolly_in");
  EXPECT_EQ(shot->segments[0].effect, "dof_change");
  ASSERT_EQ(shot->segments[0].subjects_px.size(), 1u);
  EXPECT_EQ(shot->segments[0].subjects_px[0], cv::Rect2d(250, 120, 90, 90));
  EXPECT_TRUE(shot->segments[1].authored());
  EXPECT_EQ(shot->segments[1].interpolation, Interpolation::kCatmullRom);
  const std::vector<double> durations = shot->SegmentDurations(8);
  ASSERT_EQ(durations.size(), 2u);
  EXPECT_DOUBLE_EQ(durations[0], 5);
  EXPECT_DOUBLE_EQ(durations[1], 3);
}

TEST(ShotFileTest, ErrorsNameTheFieldAndTheValue) {
  struct Case {
    std::string json_pointer;
    nlohmann::json value;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"/segments/1/keyframes/0/focal_scale", "wide", "shot.segments[1].keyframes[0].focal_scale"},
      {"/segments/0/move", "barrel_roll", "barrel_roll"},
      {"/format", "mp4", "format"},
      {"/segments/1/keyframes/1/t", 1.5, "shot.segments[1].keyframes[2].t: 1.000000 does not increase"},
      {"/segments/0/bogus", 1, "bogus"},
  };
  for (const Case& c : cases) {
    nlohmann::json j = TwoSegmentShot();
    j[nlohmann::json::json_pointer(c.json_pointer)] = c.value;
    StatusOr<Shot> shot = ShotFromJson(j);
    ASSERT_FALSE(shot.ok()) << c.json_pointer;
    EXPECT_EQ(shot.status().code(), StatusCode::kInvalidArgument) << c.json_pointer;
    EXPECT_NE(shot.status().message().find(c.expected), std::string::npos)
        << c.json_pointer << ": " << shot.status().message();
  }
  nlohmann::json both = TwoSegmentShot();
  both["segments"][0]["keyframes"] = both["segments"][1]["keyframes"];
  StatusOr<Shot> shot = ShotFromJson(both);
  ASSERT_FALSE(shot.ok());
  EXPECT_NE(shot.status().message().find("shot.segments[0]: give either keyframes or a move"), std::string::npos)
      << shot.status().message();
}

TEST(ShotFileTest, KeyframesFollowACubicSplineThroughEveryKey) {
  StatusOr<Shot> shot = ShotFromJson(TwoSegmentShot());
  ASSERT_TRUE(shot.ok());
  StatusOr<std::vector<CameraKeyframe>> keys = ResolveKeyframes(shot->segments[1], 400.0, "shot.segments[1]");
  ASSERT_TRUE(keys.ok()) << keys.status().ToString();
  ASSERT_EQ(keys->size(), 3u);
  EXPECT_DOUBLE_EQ((*keys)[0].focal_px, 600.0);  // focal_scale 1.5 of f = 400
  // focus_at (0, 0, 1.5), looked at from (0.02, 0, 0.05): its distance along the axis.
  EXPECT_NEAR((*keys)[1].focus_depth_m, std::hypot(0.02, 1.45), 1e-9);
  CameraPath path = BlankPath(PathKind::kNovelView, "shot", CameraModel::Pinhole(640, 480, 400), 30, 3);
  path.keyframes = *keys;
  path.interpolation = Interpolation::kCatmullRom;
  ASSERT_TRUE(path.Validate().ok());
  // Through every key, and curved between them (a straight line would put t = 0.25 half-way).
  for (const CameraKeyframe& key : path.keyframes) {
    EXPECT_LT((CameraCentre(path.PoseAt(key.t)) - key.centre_in_world).norm(), 1e-9) << key.t;
  }
  const Eigen::Vector3d linear = 0.5 * (path.keyframes[0].centre_in_world + path.keyframes[1].centre_in_world);
  EXPECT_GT((CameraCentre(path.PoseAt(0.25)) - linear).norm(), 1e-4);
  path.interpolation = Interpolation::kLinear;
  EXPECT_LT((CameraCentre(path.PoseAt(0.25)) - linear).norm(), 1e-9);
}

TEST(ShotFileTest, TheWrittenShotOfAPathReplaysThatPath) {
  StatusOr<Shot> shot = ShotFromJson(TwoSegmentShot());
  ASSERT_TRUE(shot.ok());
  StatusOr<std::vector<CameraKeyframe>> keys = ResolveKeyframes(shot->segments[1], 400.0, "shot.segments[1]");
  ASSERT_TRUE(keys.ok());
  CameraPath path = BlankPath(PathKind::kNovelView, "shot", CameraModel::Pinhole(640, 480, 400), 30, 3);
  path.keyframes = *keys;
  ColorEffect saturation;
  saturation.kind = ColorEffectKind::kSaturation;
  saturation.region_min_in_world = {-0.1, -0.1, 1.4};
  saturation.region_max_in_world = {0.1, 0.1, 1.6};
  saturation.falloff_m = 0.05;
  for (size_t k = 0; k < path.keyframes.size(); ++k) {
    saturation.amount = 1.0 + 0.3 * static_cast<double>(k);
    path.keyframes[k].effects = {saturation};
  }
  ASSERT_TRUE(path.Validate().ok());
  // Written as text and read back, as `parallax clip` writes it beside the clip.
  const std::string text = ShotToJson(ShotFromPath(path)).dump();
  StatusOr<Shot> replayed = ShotFromJson(nlohmann::json::parse(text));
  ASSERT_TRUE(replayed.ok()) << replayed.status().ToString() << "\n" << text;
  ASSERT_EQ(replayed->segments.size(), 1u);
  StatusOr<std::vector<CameraKeyframe>> again = ResolveKeyframes(replayed->segments[0], 400.0, "replayed");
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  CameraPath same = path;
  same.keyframes = *again;
  same.interpolation = replayed->segments[0].interpolation;
  for (int i = 0; i < path.NumFrames(); ++i) {
    const double t = path.FrameTime(i);
    EXPECT_LT((CameraCentre(same.PoseAt(t)) - CameraCentre(path.PoseAt(t))).norm(), 1e-6) << t;
    EXPECT_LT(same.PoseAt(t).rotation.angularDistance(path.PoseAt(t).rotation), 1e-6) << t;
    EXPECT_NEAR(same.FocalAt(t), path.FocalAt(t), 1e-6) << t;
  }
  for (size_t k = 0; k < path.keyframes.size(); ++k) {
    ASSERT_EQ(same.keyframes[k].effects.size(), 1u);
    EXPECT_NEAR(same.keyframes[k].effects[0].amount, path.keyframes[k].effects[0].amount, 1e-9);
    EXPECT_NEAR(same.keyframes[k].aperture_m, path.keyframes[k].aperture_m, 1e-9);
  }
}

}  // namespace
}  // namespace px::direct
