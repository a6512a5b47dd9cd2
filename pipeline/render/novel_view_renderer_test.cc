#include "pipeline/render/novel_view_renderer.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "pipeline/render/plane_scene_testing.h"

namespace px {
namespace {

using render::testing::MakeLatticeViews;
using render::testing::PlaneScene;

// Half the Pop9 tile (640x480, f 560) keeps the tests fast with the same angles.
const CameraModel kCamera = CameraModel::Pinhole(320, 240, 280);
constexpr double kBaselineM = 0.025;

double Psnr(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  diff.convertTo(diff, CV_32F);
  diff = diff.mul(diff);
  double total = 0;
  int count = 0;
  for (int y = 0; y < a.rows; ++y) {
    for (int x = 0; x < a.cols; ++x) {
      if (!mask.empty() && mask.at<uint8_t>(y, x) == 0) continue;
      const cv::Vec3f d = diff.at<cv::Vec3f>(y, x);
      total += d[0] + d[1] + d[2];
      count += 3;
    }
  }
  const double mse = total / std::max(count, 1);
  return mse <= 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

// Pixels more than 2 px from a depth discontinuity of the exact target depth. Silhouettes are
// only defined to about a pixel by point sampling, so errors there measure sampling, not geometry.
cv::Mat AwayFromEdges(const cv::Mat& depth_m) {
  cv::Mat edges(depth_m.size(), CV_8U, cv::Scalar(0));
  for (int y = 0; y < depth_m.rows; ++y) {
    for (int x = 0; x < depth_m.cols; ++x) {
      const float z = depth_m.at<float>(y, x);
      const float right = depth_m.at<float>(y, std::min(x + 1, depth_m.cols - 1));
      const float down = depth_m.at<float>(std::min(y + 1, depth_m.rows - 1), x);
      if (std::abs(z - right) > 0.1f * z || std::abs(z - down) > 0.1f * z) edges.at<uint8_t>(y, x) = 255;
    }
  }
  cv::dilate(edges, edges, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)));
  return edges == 0;
}

class NovelViewRendererTest : public ::testing::Test {
 protected:
  void SetUp() override { MakeLatticeViews(scene_, 3, 3, kBaselineM, kCamera, &views_, &depths_); }
  PlaneScene scene_;
  std::vector<View> views_;
  std::vector<DepthMap> depths_;
};

TEST_F(NovelViewRendererTest, ViewBetweenSourcesMatchesTheExactRender) {
  // Between the lenses, turned 1 degree and zoomed 5 %: exercises the full warp.
  const Eigen::Vector3d centre(0.011, 0.006, 0.0);
  const Eigen::Quaterniond rotation(Eigen::AngleAxisd(M_PI / 180, Eigen::Vector3d::UnitY()));
  const Rigid3 pose(rotation, -(rotation * centre));
  CameraModel camera = kCamera;
  camera.fx = camera.fy = 294;
  StatusOr<RenderResult> result = RenderNovelView(views_, depths_, camera, pose, RenderOptions{});
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  cv::Mat want_bgr, want_depth;
  scene_.Render(camera, pose, &want_bgr, &want_depth);

  const cv::Mat interior = AwayFromEdges(want_depth);
  // Smooth regions: the error is bilinear interpolation of ~15 px sinusoids (at most 1-2
  // levels) plus 8-bit rounding twice, about 45-50 dB (measured 49.9); a sideways shift of half
  // a pixel drops the background to 34 dB, so 44 dB separates right from wrong geometry.
  EXPECT_GT(Psnr(result->bgr, want_bgr, interior), 44.0);
  // Whole frame, silhouettes included, where a pixel may land on either side (measured 40.0).
  EXPECT_GT(Psnr(result->bgr, want_bgr, cv::Mat()), 35.0);
  // Three sources straddle the target: it sees almost nothing they miss (a sliver at the
  // right border from the 1 degree turn, and disoccluded rims).
  EXPECT_LT(result->hole_ratio, 0.02);
  ASSERT_EQ(result->sources.size(), 3u);
  EXPECT_EQ(result->sources[0].value, 4);  // the centre lens is nearest

  // Depth of covered interior pixels is the exact plane depth, up to float rounding.
  double max_rel_error = 0;
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      if (!interior.at<uint8_t>(y, x) || !result->coverage.at<uint8_t>(y, x)) continue;
      const double want = want_depth.at<float>(y, x);
      max_rel_error = std::max(max_rel_error, std::abs(result->depth_m.at<float>(y, x) - want) / want);
    }
  }
  EXPECT_LT(max_rel_error, 1e-3);
}

TEST_F(NovelViewRendererTest, SourcePoseWithThatSourceLeftOutReproducesIt) {
  RenderOptions options;
  options.num_source_views = 4;  // the four edge neighbours are equally near; take them all
  StatusOr<std::unique_ptr<NovelViewRenderer>> renderer = NovelViewRenderer::Create(views_, depths_, options);
  ASSERT_TRUE(renderer.ok()) << renderer.status().ToString();
  const View& centre = views_[4];
  StatusOr<RenderResult> result = (*renderer)->Render(centre.camera, centre.cam_from_world, centre.id);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  for (ViewId id : result->sources) EXPECT_NE(id, centre.id);
  const cv::Mat interior = AwayFromEdges(depths_[4].depth_m);
  // Same bounds and reasons as between the sources (measured 53.0 and 53.1).
  EXPECT_GT(Psnr(result->bgr, centre.image, interior), 44.0);
  EXPECT_GT(Psnr(result->bgr, centre.image, cv::Mat()), 35.0);
  EXPECT_LT(result->hole_ratio, 0.01);

  // With the source itself in the set it dominates the blend (the others weigh 1e-3 or less)
  // and samples itself at whole pixels: its own image up to rounding.
  StatusOr<RenderResult> with_self = (*renderer)->Render(centre.camera, centre.cam_from_world);
  ASSERT_TRUE(with_self.ok());
  EXPECT_EQ(with_self->sources[0], centre.id);
  EXPECT_GT(Psnr(with_self->bgr, centre.image, cv::Mat()), 50.0);
  EXPECT_EQ(with_self->hole_ratio, 0.0);
}

TEST_F(NovelViewRendererTest, FarOutsideTheRigHolesAppearWhereNoSourceLooked) {
  RenderOptions options;
  options.num_source_views = 9;  // all sources, so the expectation below needs no selection rule
  StatusOr<std::unique_ptr<NovelViewRenderer>> renderer = NovelViewRenderer::Create(views_, depths_, options);
  ASSERT_TRUE(renderer.ok()) << renderer.status().ToString();
  // 30 cm to the left: twelve baselines outside the rig.
  const Rigid3 pose(Eigen::Quaterniond::Identity(), -Eigen::Vector3d(-0.30, 0, 0));
  StatusOr<RenderResult> result = (*renderer)->Render(kCamera, pose);
  ASSERT_TRUE(result.ok()) << result.status().ToString();

  // Exact expectation: a target pixel is seen by some source when its surface point projects
  // inside that source's image and nothing blocks the source's line of sight to it.
  cv::Mat want_holes(kCamera.height, kCamera.width, CV_8U, cv::Scalar(0));
  const Eigen::Vector3d target_centre = CameraCentre(pose);
  for (int v = 0; v < kCamera.height; ++v) {
    for (int u = 0; u < kCamera.width; ++u) {
      Eigen::Vector3d p;
      bool foreground = false;
      const Eigen::Vector3d ray((u - kCamera.cx) / kCamera.fx, (v - kCamera.cy) / kCamera.fy, 1);
      ASSERT_TRUE(scene_.Cast(target_centre, ray, &p, &foreground));
      bool seen = false;
      for (const View& view : views_) {
        Eigen::Vector2d pixel;
        if (!view.camera.Project(view.cam_from_world * p, &pixel)) continue;
        if (pixel.x() < 0 || pixel.y() < 0 || pixel.x() > kCamera.width - 1 || pixel.y() > kCamera.height - 1) continue;
        if (scene_.Visible(CameraCentre(view.cam_from_world), p)) {
          seen = true;
          break;
        }
      }
      if (!seen) want_holes.at<uint8_t>(v, u) = 255;
    }
  }
  const double want_ratio = cv::countNonZero(want_holes) / static_cast<double>(want_holes.total());
  // The disocclusion beside the foreground (~50 px wide) and the strip past the rig's field of
  // view at the left border (~26 px) make about an eighth of the frame.
  ASSERT_GT(want_ratio, 0.08);
  const cv::Mat got_holes = result->coverage == 0;
  const double got_ratio = cv::countNonZero(got_holes) / static_cast<double>(got_holes.total());
  EXPECT_DOUBLE_EQ(result->hole_ratio, got_ratio);
  // Hole outlines are resolved to about a pixel (quads end at pixel centres, silhouettes are
  // point sampled); a one-pixel band around the ~700 px outline is 7 % of the ~9400 px area, so
  // allow 5 % on the ratio and an overlap (IoU) of 0.93. Measured: 0.1219 vs 0.1198, IoU 0.983.
  EXPECT_NEAR(result->hole_ratio, want_ratio, 0.05 * want_ratio);
  const double intersection = cv::countNonZero(got_holes & want_holes);
  const double union_area = cv::countNonZero(got_holes | want_holes);
  EXPECT_GT(intersection / union_area, 0.93);
  // Large holes score high on the paper's metric; the view between the sources scores ~0.
  EXPECT_GT(result->hole_score, 2.0);
  // Holes are disocclusions of the background and the strip past the rig's view of it: they
  // fill from the background, never from the foreground (1 m) beside them.
  int filled_as_background = 0;
  for (int v = 0; v < kCamera.height; ++v) {
    for (int u = 0; u < kCamera.width; ++u) {
      if (got_holes.at<uint8_t>(v, u) && std::abs(result->depth_m.at<float>(v, u) - scene_.background_z) < 0.1) {
        ++filled_as_background;
      }
    }
  }
  EXPECT_EQ(filled_as_background, cv::countNonZero(got_holes));
  // Every hole was filled: no black pixels remain (the scene has no black).
  cv::Mat grey;
  cv::cvtColor(result->bgr, grey, cv::COLOR_BGR2GRAY);
  EXPECT_EQ(cv::countNonZero(grey == 0), 0);
}

TEST_F(NovelViewRendererTest, RendersAreDeterministic) {
  StatusOr<std::unique_ptr<NovelViewRenderer>> renderer = NovelViewRenderer::Create(views_, depths_, RenderOptions{});
  ASSERT_TRUE(renderer.ok());
  const Rigid3 pose(Eigen::Quaterniond::Identity(), -Eigen::Vector3d(-0.05, 0.01, 0.02));
  StatusOr<RenderResult> a = (*renderer)->Render(kCamera, pose);
  StatusOr<RenderResult> b = (*renderer)->Render(kCamera, pose);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(cv::norm(a->bgr, b->bgr, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a->depth_m, b->depth_m, cv::NORM_INF), 0.0);
}

TEST_F(NovelViewRendererTest, RejectsBadInput) {
  std::vector<DepthMap> missing(depths_.begin(), depths_.end() - 1);
  Status status = NovelViewRenderer::Create(views_, missing, {}).status();
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("view 8: no depth map"), std::string::npos) << status.message();

  std::vector<View> distorted = views_;
  distorted[2].camera.distortion[0] = 0.1;
  status = NovelViewRenderer::Create(distorted, depths_, {}).status();
  EXPECT_NE(status.message().find("view 2: camera has lens distortion"), std::string::npos) << status.message();

  std::vector<View> small = views_;
  small[1].image = cv::Mat(10, 10, CV_8UC3);
  status = NovelViewRenderer::Create(small, depths_, {}).status();
  EXPECT_NE(status.message().find("view 1: image is 10x10"), std::string::npos) << status.message();

  RenderOptions options;
  options.soft_z_band = 0;
  EXPECT_NE(NovelViewRenderer::Create(views_, depths_, options).status().message().find("render.soft_z_band"),
            std::string::npos);

  StatusOr<std::unique_ptr<NovelViewRenderer>> one =
      NovelViewRenderer::Create({views_[0]}, {depths_[0]}, RenderOptions{});
  ASSERT_TRUE(one.ok());
  EXPECT_EQ((*one)->Render(kCamera, Rigid3(), views_[0].id).status().code(), StatusCode::kFailedPrecondition);
}

}  // namespace
}  // namespace px
