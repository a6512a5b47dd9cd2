#include "pipeline/run/palette_dither.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/run/image_set_scale.h"

namespace px {
namespace {

// A photo-like 160x120 image: smooth colour ramps with a few hard-edged rectangles.
cv::Mat SmoothPicture() {
  cv::Mat bgr(120, 160, CV_8UC3);
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) {
      bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uint8_t>(40 + x),
                                          static_cast<uint8_t>(30 + 1.5 * y),
                                          static_cast<uint8_t>(128 + 60 * std::sin(0.05 * (x + y))));
    }
  }
  cv::rectangle(bgr, cv::Rect(20, 20, 40, 30), cv::Scalar(30, 200, 90), cv::FILLED);
  cv::rectangle(bgr, cv::Rect(100, 60, 30, 40), cv::Scalar(220, 40, 160), cv::FILLED);
  return bgr;
}

// Six levels per channel (216 colours, a web palette). Dithered: a checkerboard threshold, so
// a level between two palette entries alternates between them from pixel to pixel.
cv::Mat Quantised(const cv::Mat& bgr, bool dither) {
  cv::Mat out(bgr.size(), CV_8UC3);
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) {
      const double offset = !dither ? 0.5 : ((x + y) % 2 == 0 ? 0.25 : 0.75);
      for (int c = 0; c < 3; ++c) {
        const double level = std::floor(bgr.at<cv::Vec3b>(y, x)[c] / 51.0 + offset);
        out.at<cv::Vec3b>(y, x)[c] = cv::saturate_cast<uint8_t>(51.0 * level);
      }
    }
  }
  return out;
}

Frame FrameOf(const cv::Mat& bgr) {
  Frame frame;
  frame.image = FromBgr(bgr, PixelFormat::kRgb888).value();
  return frame;
}

TEST(PaletteDitherTest, CountsColoursUpToTheLimit) {
  EXPECT_LE(CountColoursUpTo(FromBgr(Quantised(SmoothPicture(), true), PixelFormat::kBgr888).value(), 256), 216);
  EXPECT_EQ(CountColoursUpTo(FromBgr(SmoothPicture(), PixelFormat::kRgb888).value(), 256), 257);
  EXPECT_EQ(CountColoursUpTo(FromBgr(SmoothPicture(), PixelFormat::kGray8).value(), 256), 257);  // not RGB
}

TEST(PaletteDitherTest, TellsADitheredPaletteFromAPlainOneAndAPhoto) {
  const cv::Mat picture = SmoothPicture();
  EXPECT_GT(PixelScaleResidual(Quantised(picture, true)), kDitherResidualLevels);
  EXPECT_LT(PixelScaleResidual(Quantised(picture, false)), kDitherResidualLevels);
  EXPECT_LT(PixelScaleResidual(picture), 3.0);
}

TEST(PaletteDitherTest, RemovingTheDitherBringsThePictureBack) {
  const cv::Mat picture = SmoothPicture();
  const cv::Mat dithered = Quantised(picture, true);
  const double before = cv::PSNR(dithered, picture);
  const double after = cv::PSNR(RemoveDither(dithered), picture);
  EXPECT_GT(after, before + 6.0) << before << " dB -> " << after << " dB";
  EXPECT_LT(PixelScaleResidual(RemoveDither(dithered)), kDitherResidualLevels);
}

TEST(PaletteDitherTest, TheWorkingImageSetHasNoDither) {
  const cv::Mat dithered = Quantised(SmoothPicture(), true);
  FrameSet shot;
  shot.kind = FrameSetKind::kImageSet;
  shot.frames = {FrameOf(dithered), FrameOf(dithered), FrameOf(SmoothPicture())};
  shot.frames[1].status = FrameStatus::kCorrupt;  // left for the stages to report
  const std::optional<WorkingImageSet> working = ImageSetAtWorkingSize(0, shot, RigCalibration{});
  ASSERT_TRUE(working.has_value());
  EXPECT_NE(working->note.find("1 of 3 frames are palette images"), std::string::npos) << working->note;
  EXPECT_EQ(working->note.find("scaled"), std::string::npos) << working->note;
  const cv::Mat first = ToBgr(working->capture.frames[0].image).value();
  EXPECT_EQ(cv::norm(first, RemoveDither(dithered), cv::NORM_INF), 0.0);
  EXPECT_EQ(ToBgr(working->capture.frames[1].image).value().at<cv::Vec3b>(5, 5), dithered.at<cv::Vec3b>(5, 5));
  EXPECT_EQ(ToBgr(working->capture.frames[2].image).value().at<cv::Vec3b>(5, 5), SmoothPicture().at<cv::Vec3b>(5, 5));

  // A palette picture without dither, or photos within the size, need nothing.
  shot.frames = {FrameOf(Quantised(SmoothPicture(), false)), FrameOf(SmoothPicture())};
  EXPECT_FALSE(ImageSetAtWorkingSize(0, shot, RigCalibration{}).has_value());
}

}  // namespace
}  // namespace px
