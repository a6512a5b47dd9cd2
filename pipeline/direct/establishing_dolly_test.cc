#include "pipeline/direct/establishing_dolly.h"

#include <gtest/gtest.h>

#include "pipeline/direct/plan_camera_path.h"

namespace px {
namespace {

// A lattice rig: lens (r, c) at x = (c - (cols-1)/2) * baseline, y likewise, all looking down +z,
// each with a constant depth map.
struct Rig {
  std::vector<View> views;
  std::vector<DepthMap> depths;
};

Rig MakeRig(int rows, int cols, double baseline_m, double depth_m) {
  Rig rig;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      View view;
      view.id.value = r * cols + c;
      view.camera = CameraModel::Pinhole(64, 48, 56);
      // Intrinsics of the centre lens differ so the test can see which one the path took.
      if (r == rows / 2 && c == cols / 2) view.camera.fx = view.camera.fy = 60;
      const Eigen::Vector3d centre((c - (cols - 1) / 2.0) * baseline_m, (r - (rows - 1) / 2.0) * baseline_m, 0);
      view.cam_from_world = Rigid3(Eigen::Quaterniond::Identity(), -centre);
      view.image = cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(128));
      DepthMap depth;
      depth.id = view.id;
      depth.depth_m = cv::Mat(48, 64, CV_32F, cv::Scalar(depth_m));
      depth.confidence = cv::Mat(48, 64, CV_32F, cv::Scalar(1));
      rig.views.push_back(view);
      rig.depths.push_back(depth);
    }
  }
  return rig;
}

TEST(EstablishingDollyTest, CrossesTheRigAlongItsLongerAxis) {
  const Rig rig = MakeRig(3, 3, 0.025, 2.0);
  DirectOptions options;
  options.converge = false;
  StatusOr<CameraPath> path = PlanEstablishingDolly(rig.views, rig.depths, options);
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  EXPECT_EQ(path->move, "establishing_dolly");
  EXPECT_LT((CameraCentre(path->PoseAt(0)) - Eigen::Vector3d(-0.025, 0, 0)).norm(), 1e-12);
  EXPECT_LT((CameraCentre(path->PoseAt(1)) - Eigen::Vector3d(0.025, 0, 0)).norm(), 1e-12);
  // Straight ahead: the rig's own orientation along the whole path.
  for (double t : {0.0, 0.5, 1.0}) {
    EXPECT_LT(path->PoseAt(t).rotation.angularDistance(Eigen::Quaterniond::Identity()), 1e-9);
  }
  // The centre lens's intrinsics.
  EXPECT_DOUBLE_EQ(path->FocalAt(0.5), 60);
  EXPECT_EQ(path->width, 64);
  EXPECT_EQ(path->height, 48);
  EXPECT_EQ(path->NumFrames(), 150);
  EXPECT_NE(path->reason.find("straight ahead"), std::string::npos) << path->reason;
}

TEST(EstablishingDollyTest, ConvergesOnTheMedianDepth) {
  const Rig rig = MakeRig(3, 3, 0.025, 2.0);
  StatusOr<CameraPath> path = PlanEstablishingDolly(rig.views, rig.depths, DirectOptions{});
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  // The point on the rig axis at the median depth stays on the principal point all along:
  // that depth is the pivot of the move. Exact at the keyframes; between them slerp turns at a
  // constant rate while atan(x / z) does not, off by ~1e-5 px here, so allow 1e-3 px.
  const Eigen::Vector3d pivot(0, 0, 2.0);
  for (double t : {0.0, 0.3, 1.0}) {
    Eigen::Vector2d pixel;
    ASSERT_TRUE(path->CameraAt(t).Project(path->PoseAt(t) * pivot, &pixel));
    EXPECT_NEAR(pixel.x(), path->cx, 1e-3) << "t=" << t;
    EXPECT_NEAR(pixel.y(), path->cy, 1e-3) << "t=" << t;
  }
  // Slightly converging: atan(25 mm / 2 m) = 0.72 degrees at each end.
  EXPECT_NEAR(RotationErrorDeg(path->PoseAt(0), Rigid3()), 0.716, 0.01);
  EXPECT_NE(path->reason.find("2.00 m"), std::string::npos) << path->reason;
}

TEST(EstablishingDollyTest, TallRigDolliesVertically) {
  const Rig rig = MakeRig(4, 2, 0.012, 1.0);
  DirectOptions options;
  options.converge = false;
  StatusOr<CameraPath> path = PlanEstablishingDolly(rig.views, rig.depths, options);
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  EXPECT_LT((CameraCentre(path->PoseAt(0)) - Eigen::Vector3d(0, -0.018, 0)).norm(), 1e-12);
  EXPECT_LT((CameraCentre(path->PoseAt(1)) - Eigen::Vector3d(0, 0.018, 0)).norm(), 1e-12);
}

TEST(EstablishingDollyTest, WithoutDepthLooksStraightAhead) {
  const Rig rig = MakeRig(1, 3, 0.025, 2.0);
  StatusOr<CameraPath> path = PlanEstablishingDolly(rig.views, {}, DirectOptions{});
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  EXPECT_LT(path->PoseAt(0).rotation.angularDistance(Eigen::Quaterniond::Identity()), 1e-9);
  EXPECT_NE(path->reason.find("no depth known"), std::string::npos) << path->reason;
}

TEST(EstablishingDollyTest, RejectsDegenerateInput) {
  Rig rig = MakeRig(1, 1, 0.025, 2.0);
  EXPECT_EQ(PlanEstablishingDolly(rig.views, rig.depths, {}).status().code(), StatusCode::kFailedPrecondition);

  rig = MakeRig(1, 3, 0.025, 2.0);
  rig.depths.pop_back();
  EXPECT_NE(PlanEstablishingDolly(rig.views, rig.depths, {}).status().message().find("3 views but 2 depth maps"),
            std::string::npos);

  rig = MakeRig(1, 3, 0.0, 2.0);  // three lenses at one point: no baseline to dolly along
  const Status status = PlanEstablishingDolly(rig.views, rig.depths, {}).status();
  EXPECT_EQ(status.code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(status.message().find("span"), std::string::npos) << status.message();
}

TEST(MedianSceneDepthTest, IgnoresUnknownDepth) {
  DepthMap map;
  map.depth_m = cv::Mat(40, 40, CV_32F, cv::Scalar(0));
  map.depth_m(cv::Rect(0, 0, 40, 30)).setTo(3.0);
  map.depth_m(cv::Rect(0, 0, 40, 10)).setTo(1.0);
  // Of the known depths, 1/3 are 1 m and 2/3 are 3 m: the median is 3 m; the zeros do not count.
  EXPECT_FLOAT_EQ(MedianSceneDepth({map}, 1), 3.0f);
  EXPECT_EQ(MedianSceneDepth({}, 1), 0.0);
}

TEST(PlanCameraPathTest, AutoSaysWhy) {
  const Rig rig = MakeRig(3, 3, 0.025, 2.0);
  StatusOr<CameraPath> path = PlanCameraPath(rig.views, rig.depths, DirectOptions{});
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  EXPECT_EQ(path->move, "establishing_dolly");
  EXPECT_EQ(path->reason.rfind("auto:", 0), 0u) << path->reason;
  DirectOptions bad;
  bad.move = "vertigo";
  EXPECT_EQ(PlanCameraPath(rig.views, rig.depths, bad).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace px
