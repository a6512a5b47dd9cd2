#include "pipeline/direct/output_frame.h"

#include <gtest/gtest.h>

namespace px {
namespace {

TEST(OutputFrameTest, SizesComeFromTheSizeOrFromAspectAndHeight) {
  OutputFrameOptions options;
  ASSERT_TRUE(ParseOutputSize("1080x1920", &options).ok());
  EXPECT_EQ(ResolveOutputSize(options, 640, 480).width, 1080);
  EXPECT_EQ(ResolveOutputSize(options, 640, 480).height, 1920);

  OutputFrameOptions portrait;
  ASSERT_TRUE(ParseOutputAspect("9:16", &portrait).ok());
  OutputSize size = ResolveOutputSize(portrait, 640, 480);  // the capture's height
  EXPECT_EQ(size.width, 270);
  EXPECT_EQ(size.height, 480);
  portrait.height = 1001;  // made even for H.264
  size = ResolveOutputSize(portrait, 640, 480);
  EXPECT_EQ(size.height, 1002);
  EXPECT_EQ(size.width, 564);

  OutputFrameOptions source;
  ASSERT_TRUE(ParseOutputAspect("source", &source).ok());
  EXPECT_EQ(ResolveOutputSize(source, 641, 479).width, 641) << "the source's size is kept as it is";
}

TEST(OutputFrameTest, BadSizesAndAspectsAreNamed) {
  OutputFrameOptions options;
  EXPECT_EQ(ParseOutputSize("1080", &options).message(), "size '1080': want WIDTHxHEIGHT, e.g. 1080x1920");
  EXPECT_FALSE(ParseOutputSize("8x8", &options).ok());
  EXPECT_EQ(ParseOutputAspect("wide", &options).message(), "aspect 'wide': want W:H (16:9, 9:16, 1:1, 4:5) or source");
  EXPECT_FALSE(ParseOutputAspect("0:9", &options).ok());
}

TEST(OutputFrameTest, TheFrameIsTheWidestCropOfItsAspectInsideTheSourceField) {
  CameraModel source = CameraModel::Pinhole(640, 480, 500);
  double scale = 0;
  // 9:16 at the source's height: same focal (the crop is narrower, not zoomed).
  CameraModel portrait = FrameOutputCamera(source, {270, 480}, &scale);
  EXPECT_DOUBLE_EQ(scale, 1.0);
  EXPECT_DOUBLE_EQ(portrait.fx, 500);
  EXPECT_DOUBLE_EQ(portrait.cx, 134.5);
  EXPECT_DOUBLE_EQ(portrait.cy, 239.5);
  // 1920x1080 from 640x480: the width decides (3x), the top and bottom are cut.
  CameraModel wide = FrameOutputCamera(source, {1920, 1080}, &scale);
  EXPECT_DOUBLE_EQ(scale, 3.0);
  EXPECT_DOUBLE_EQ(wide.fx, 1500);
  // The output's corners see directions the source saw.
  const double half_fov_x = 0.5 * wide.width / wide.fx;
  const double half_fov_y = 0.5 * wide.height / wide.fy;
  EXPECT_LE(half_fov_x, 0.5 * source.width / source.fx + 1e-12);
  EXPECT_LE(half_fov_y, 0.5 * source.height / source.fy + 1e-12);
}

}  // namespace
}  // namespace px
