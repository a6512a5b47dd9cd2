#include "pipeline/core/virtual_camera.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace px {
namespace {

using ::testing::HasSubstr;

VirtualCamera Pinhole() {
  VirtualCamera camera;
  camera.camera = CameraModel::Pinhole(64, 48, 60);
  return camera;
}

TEST(VirtualCamera, PinholeWithEffectsIsValid) {
  VirtualCamera camera = Pinhole();
  ColorEffect dim;
  dim.kind = ColorEffectKind::kBrightness;
  dim.amount = 0.5;
  dim.region_min_in_world = Eigen::Vector3d(-0.1, -0.1, 0.9);
  dim.region_max_in_world = Eigen::Vector3d(0.1, 0.1, 1.1);
  dim.invert = true;
  camera.effects.push_back(dim);
  camera.aperture_m = 0.01;
  camera.focus_depth_m = 1.0;
  EXPECT_TRUE(camera.Validate().ok()) << camera.Validate().ToString();
}

TEST(VirtualCamera, BadFieldsAreNamed) {
  VirtualCamera camera = Pinhole();
  camera.aperture_m = 0.01;
  EXPECT_THAT(camera.Validate().message(), HasSubstr("focus_depth_m"));
  camera = Pinhole();
  camera.camera.distortion[0] = 0.1;
  EXPECT_THAT(camera.Validate().message(), HasSubstr("without distortion"));
  camera = Pinhole();
  ColorEffect inverted_box;
  inverted_box.region_min_in_world = Eigen::Vector3d(1, 0, 0);
  camera.effects.push_back(inverted_box);
  EXPECT_THAT(camera.Validate().message(), HasSubstr("saturation: region is not a box"));
}

TEST(VirtualCamera, EffectKindNamesRoundTrip) {
  for (ColorEffectKind kind : {ColorEffectKind::kSaturation, ColorEffectKind::kBrightness}) {
    EXPECT_EQ(ParseColorEffectKind(ColorEffectKindName(kind)).value(), kind);
  }
  EXPECT_FALSE(ParseColorEffectKind("sepia").ok());
}

}  // namespace
}  // namespace px
