#include "pipeline/core/pixel_format.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace px {
namespace {

// A smooth colour image: the conversions lose only chroma resolution on it.
cv::Mat SmoothImage(int width, int height) {
  cv::Mat image(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      image.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uint8_t>(40 + 150 * x / width),
                                            static_cast<uint8_t>(60 + 120 * y / height),
                                            static_cast<uint8_t>(200 - 100 * (x + y) / (width + height)));
    }
  }
  return image;
}

class PixelFormatRoundTrip : public ::testing::TestWithParam<PixelFormat> {};

TEST_P(PixelFormatRoundTrip, EncodeThenDecodeIsClose) {
  const cv::Mat bgr = SmoothImage(64, 48);
  StatusOr<RawImage> raw = FromBgr(bgr, GetParam());
  ASSERT_TRUE(raw.ok()) << raw.status().ToString();
  ASSERT_TRUE(raw->Validate().ok());
  StatusOr<cv::Mat> back = ToBgr(*raw);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  if (GetParam() == PixelFormat::kGray8) return;  // colour is gone by design
  // Bayer demosaicing is least exact at the border; compare the interior.
  cv::Rect inner(2, 2, 60, 44);
  EXPECT_GT(cv::PSNR(bgr(inner), (*back)(inner)), 35.0) << PixelFormatName(GetParam());
}

INSTANTIATE_TEST_SUITE_P(AllFormats,
                         PixelFormatRoundTrip,
                         ::testing::Values(PixelFormat::kRgb888,
                                           PixelFormat::kBgr888,
                                           PixelFormat::kGray8,
                                           PixelFormat::kYuyv,
                                           PixelFormat::kNv12,
                                           PixelFormat::kBayerRggb8));

TEST(PixelFormatTest, NamesRoundTrip) {
  for (auto f : {PixelFormat::kRgb888, PixelFormat::kYuyv, PixelFormat::kNv12, PixelFormat::kBayerRggb8}) {
    EXPECT_EQ(ParsePixelFormat(PixelFormatName(f)), f);
  }
  EXPECT_FALSE(ParsePixelFormat("MJPEG").has_value());
}

TEST(PixelFormatTest, ShortBufferIsDataLossNamingTheSizes) {
  RawImage raw;
  raw.format = PixelFormat::kNv12;
  raw.width = 64;
  raw.height = 48;
  raw.bytes.resize(100);
  Status s = raw.Validate();
  EXPECT_EQ(s.code(), StatusCode::kDataLoss);
  EXPECT_NE(s.message().find("100 bytes, want 4608"), std::string::npos) << s.message();
  EXPECT_FALSE(ToBgr(raw).ok());
}

TEST(PixelFormatTest, OddSizesAreRejectedForSubsampledFormats) {
  EXPECT_FALSE(PackedImageBytes(PixelFormat::kYuyv, 63, 48).ok());
  EXPECT_FALSE(PackedImageBytes(PixelFormat::kNv12, 64, 47).ok());
  EXPECT_TRUE(PackedImageBytes(PixelFormat::kRgb888, 63, 47).ok());
}

}  // namespace
}  // namespace px
