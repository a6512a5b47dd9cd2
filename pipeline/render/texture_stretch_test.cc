#include "pipeline/render/texture_stretch.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

namespace px::render {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Matrix3d Intrinsics(double focal_px) {
  Eigen::Matrix3d k;
  k << focal_px, 0, 320, 0, focal_px, 240, 0, 0, 1;
  return k;
}

// A plane seen by a source camera at the origin (looking along +z) and by an output camera that
// faces it squarely from `distance` along its normal: the output pixel -> source pixel homography
// at the plane's point (0, 0, 1), and the uniform magnification a face-on surface would get there.
struct PlaneViews {
  Eigen::Matrix3d novel_to_source;
  Eigen::Vector2d centre_px;
  double uniform_magnification;
};

PlaneViews FaceOnView(double tilt_rad, double distance, double source_focal, double novel_focal) {
  // The plane through P = (0, 0, 1) with its normal turned by `tilt` about the y axis from -z.
  const Eigen::Vector3d point(0, 0, 1);
  const Eigen::Vector3d normal(std::sin(tilt_rad), 0, -std::cos(tilt_rad));
  // The output camera at P - distance * normal... looking along the normal reversed (at the plane).
  const Eigen::Vector3d novel_centre = point + distance * normal;
  const Eigen::Vector3d forward = -normal;
  const Eigen::Vector3d right = Eigen::Vector3d::UnitY().cross(forward).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d world_from_novel;
  world_from_novel.col(0) = right;
  world_from_novel.col(1) = down;
  world_from_novel.col(2) = forward;
  // Source = world. X_s = R X_n + t.
  const Eigen::Matrix3d r = world_from_novel;
  const Eigen::Vector3d t = novel_centre;
  const double d = normal.dot(point);  // plane: normal . X_s = d
  const Eigen::Matrix3d h = Intrinsics(source_focal) * (r + t * normal.transpose() * r / (d - normal.dot(t))) *
                            Intrinsics(novel_focal).inverse();
  const Eigen::Vector3d in_novel = r.transpose() * (point - t);
  PlaneViews views;
  views.novel_to_source = h;
  views.centre_px = (Intrinsics(novel_focal) * in_novel).hnormalized();
  views.uniform_magnification = novel_focal / source_focal * point.z() / in_novel.z();
  return views;
}

TEST(TextureStretchTest, AFaceOnSurfaceSeenFromNearerWithALongerLensIsNotStretched) {
  // Magnified 1.5 x 4 = 6 times, evenly: a close-up, not a streak.
  const PlaneViews views = FaceOnView(0.0, 0.25, 500, 750);
  EXPECT_NEAR(TextureStretch(views.novel_to_source, views.centre_px, views.uniform_magnification), 1.0, 1e-6);
  EXPECT_EQ(TextureWeight(1.0, TextureStretchOptions{}), 1.0f);
}

TEST(TextureStretchTest, ASurfaceItsViewSawNearlyEdgeOnIsStretchedAndFaded) {
  // Tilted 80 degrees away from the source: each source texel spans 1 / cos 80 = 5.8 output pixels.
  const PlaneViews steep = FaceOnView(80.0 * kPi / 180.0, 1.0, 500, 500);
  const double stretch = TextureStretch(steep.novel_to_source, steep.centre_px, steep.uniform_magnification);
  EXPECT_NEAR(stretch, 1.0 / std::cos(80.0 * kPi / 180.0), 1e-3);
  TextureStretchOptions options;
  options.fade_from = 3;
  options.fade_to = 6;
  EXPECT_NEAR(TextureWeight(stretch, options), (6 - stretch) / 3, 1e-5);
  // At 60 degrees the stretch is 2: drawn in full.
  const PlaneViews moderate = FaceOnView(60.0 * kPi / 180.0, 1.0, 500, 500);
  EXPECT_NEAR(TextureStretch(moderate.novel_to_source, moderate.centre_px, moderate.uniform_magnification), 2.0, 1e-3);
  // Beyond fade_to nothing is drawn; with fade_from = 0 everything is.
  EXPECT_EQ(TextureWeight(8.0, options), 0.0f);
  options.fade_from = 0;
  EXPECT_EQ(TextureWeight(8.0, options), 1.0f);
}

TEST(TextureStretchTest, ASurfaceTheOutputSeesMoreObliquelyThanItsViewIsNotStretched) {
  // The reverse: the output camera compresses the texture, which is never a streak.
  Eigen::Matrix3d compress = Eigen::Matrix3d::Identity();
  compress(0, 0) = 5.0;  // five source pixels per output pixel across x
  EXPECT_NEAR(TextureStretch(compress, Eigen::Vector2d(100, 100), 1.0), 1.0, 1e-9);
}

}  // namespace
}  // namespace px::render
