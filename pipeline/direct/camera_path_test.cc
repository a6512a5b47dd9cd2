#include "pipeline/direct/camera_path.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

namespace px {
namespace {

CameraPath TwoKeyframePath() {
  CameraPath path;
  path.move = "establishing_dolly";
  path.reason = "test";
  path.width = 640;
  path.height = 480;
  path.cx = 319.5;
  path.cy = 239.5;
  path.aspect = 1.0;
  path.fps = 30;
  path.duration_s = 5;
  CameraKeyframe a;
  a.t = 0;
  a.centre_in_world = {-0.1, 0, 0};
  a.focal_px = 500;
  CameraKeyframe b;
  b.t = 1;
  b.centre_in_world = {0.1, 0.02, 0.3};
  b.cam_from_world_rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()));
  b.focal_px = 700;
  path.keyframes = {a, b};
  return path;
}

TEST(NumFramesTest, RoundsFpsTimesDuration) {
  EXPECT_EQ(NumFrames(30, 5), 150);
  EXPECT_EQ(NumFrames(25, 1.2), 30);
  EXPECT_EQ(NumFrames(29.97, 5), 150);
  EXPECT_EQ(NumFrames(30, 0.001), 1);  // never zero frames
}

TEST(CameraPathTest, EndpointsAreTheKeyframes) {
  const CameraPath path = TwoKeyframePath();
  ASSERT_TRUE(path.Validate().ok()) << path.Validate().ToString();
  for (int i = 0; i < 2; ++i) {
    const Rigid3 pose = path.PoseAt(i);
    EXPECT_LT((CameraCentre(pose) - path.keyframes[i].centre_in_world).norm(), 1e-12);
    EXPECT_LT(pose.rotation.angularDistance(path.keyframes[i].cam_from_world_rotation), 1e-12);
    EXPECT_DOUBLE_EQ(path.FocalAt(i), path.keyframes[i].focal_px);
  }
  // Outside [0, 1] the path holds its ends.
  EXPECT_LT((CameraCentre(path.PoseAt(-1)) - path.keyframes[0].centre_in_world).norm(), 1e-12);
  EXPECT_LT((CameraCentre(path.PoseAt(2)) - path.keyframes[1].centre_in_world).norm(), 1e-12);
}

TEST(CameraPathTest, InterpolatesLinearly) {
  const CameraPath path = TwoKeyframePath();
  const Rigid3 mid = path.PoseAt(0.25);
  const Eigen::Vector3d want = 0.75 * path.keyframes[0].centre_in_world + 0.25 * path.keyframes[1].centre_in_world;
  EXPECT_LT((CameraCentre(mid) - want).norm(), 1e-12);
  EXPECT_NEAR(path.FocalAt(0.25), 550, 1e-9);
  // Slerp: a quarter of the 0.2 rad turn about y.
  EXPECT_NEAR(mid.rotation.angularDistance(Eigen::Quaterniond::Identity()), 0.05, 1e-9);
  const CameraModel camera = path.CameraAt(0.25);
  EXPECT_EQ(camera.width, 640);
  EXPECT_NEAR(camera.fx, 550, 1e-9);
  EXPECT_NEAR(camera.fy, 550, 1e-9);
  EXPECT_TRUE(camera.Validate().ok());
}

TEST(CameraPathTest, ThreeKeyframesUseTheBracketingPair) {
  CameraPath path = TwoKeyframePath();
  CameraKeyframe middle = path.keyframes[0];
  middle.t = 0.5;
  middle.centre_in_world = {0, 1, 0};
  middle.focal_px = 1000;
  path.keyframes.insert(path.keyframes.begin() + 1, middle);
  ASSERT_TRUE(path.Validate().ok());
  EXPECT_NEAR(path.FocalAt(0.25), 750, 1e-9);
  EXPECT_NEAR(path.FocalAt(0.75), 850, 1e-9);
  EXPECT_NEAR(CameraCentre(path.PoseAt(0.5)).y(), 1.0, 1e-12);
}

TEST(CameraPathTest, FrameTimesSpanZeroToOne) {
  const CameraPath path = TwoKeyframePath();
  ASSERT_EQ(path.NumFrames(), 150);
  EXPECT_EQ(path.FrameTime(0), 0.0);
  EXPECT_EQ(path.FrameTime(149), 1.0);
  EXPECT_NEAR(path.FrameTime(1), 1.0 / 149, 1e-15);
}

TEST(CameraPathTest, ValidateNamesTheProblem) {
  CameraPath path = TwoKeyframePath();
  path.keyframes[1].focal_px = -3;
  EXPECT_NE(path.Validate().message().find("keyframes[1].focal_px"), std::string::npos);
  path = TwoKeyframePath();
  path.keyframes.pop_back();
  EXPECT_NE(path.Validate().message().find("1 keyframes"), std::string::npos);
  path = TwoKeyframePath();
  path.width = 0;
  EXPECT_EQ(path.Validate().code(), StatusCode::kInvalidArgument);
}

TEST(CameraPathJsonTest, RoundTrips) {
  const CameraPath path = TwoKeyframePath();
  const nlohmann::json j = CameraPathToJson(path);
  EXPECT_EQ(j.at("num_frames"), 150);
  StatusOr<CameraPath> back = CameraPathFromJson(nlohmann::json::parse(j.dump()));
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->move, path.move);
  EXPECT_EQ(back->reason, path.reason);
  EXPECT_EQ(back->width, 640);
  ASSERT_EQ(back->keyframes.size(), 2u);
  for (double t : {0.0, 0.3, 1.0}) {
    EXPECT_LT((CameraCentre(back->PoseAt(t)) - CameraCentre(path.PoseAt(t))).norm(), 1e-12);
    EXPECT_LT(back->PoseAt(t).rotation.angularDistance(path.PoseAt(t).rotation), 1e-9);
    EXPECT_NEAR(back->FocalAt(t), path.FocalAt(t), 1e-12);
  }
}

TEST(CameraPathJsonTest, TimingRoundTripsAndAPathWrittenWithoutItIsTheLinearMovePlayedOnce) {
  CameraPath path = TwoKeyframePath();
  path.timing = {ClipStyle::kBoomerang, ClipEase::kSmooth, 0};
  nlohmann::json j = CameraPathToJson(path);
  EXPECT_EQ(j.at("num_frames"), 299);
  StatusOr<CameraPath> back = CameraPathFromJson(j);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->timing.style, ClipStyle::kBoomerang);
  EXPECT_EQ(back->timing.ease, ClipEase::kSmooth);
  j.erase("style");
  j.erase("ease");
  j.erase("hold_s");
  back = CameraPathFromJson(j);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->timing.style, ClipStyle::kOnce);
  EXPECT_EQ(back->timing.ease, ClipEase::kLinear);
  EXPECT_EQ(back->NumFrames(), 150);
}

TEST(CameraPathJsonTest, MissingFieldIsNamed) {
  nlohmann::json j = CameraPathToJson(TwoKeyframePath());
  j["keyframes"][1].erase("focal_px");
  StatusOr<CameraPath> back = CameraPathFromJson(j);
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.status().message().find("camera_path.keyframes[1].focal_px"), std::string::npos)
      << back.status().message();
}

TEST(DirectOptionsTest, ValidateNamesTheField) {
  DirectOptions options;
  EXPECT_TRUE(options.Validate().ok());
  options.move = "barrel_roll";
  EXPECT_NE(options.Validate().message().find("direct.move"), std::string::npos);
  options = {};
  options.fps = 0;
  EXPECT_NE(options.Validate().message().find("direct.fps"), std::string::npos);
  options = {};
  options.duration_s = -1;
  EXPECT_NE(options.Validate().message().find("direct.duration_s"), std::string::npos);
}

}  // namespace
}  // namespace px
