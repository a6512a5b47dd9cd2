#include "eval/render/image_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace px::eval {
namespace {

cv::Mat Texture(int width, int height) {
  cv::Mat image(height, width, CV_8UC3);
  cv::randu(image, cv::Scalar::all(0), cv::Scalar::all(255));
  cv::GaussianBlur(image, image, cv::Size(0, 0), 1.5);
  return image;
}

TEST(ImageMetricsTest, PsnrOfAKnownError) {
  const cv::Mat a(20, 30, CV_8UC3, cv::Scalar(100, 100, 100));
  cv::Mat b = a.clone();
  EXPECT_EQ(Psnr(a, b), 99.0);
  b += cv::Scalar(10, 10, 10);  // MSE 100
  EXPECT_NEAR(Psnr(a, b), 10 * std::log10(255.0 * 255.0 / 100.0), 1e-9);
  // Masked: the error only outside the mask does not count.
  cv::Mat c = a.clone();
  c(cv::Rect(0, 0, 10, 20)).setTo(cv::Scalar(0, 0, 0));
  cv::Mat mask(20, 30, CV_8U, cv::Scalar(255));
  mask(cv::Rect(0, 0, 10, 20)).setTo(0);
  EXPECT_EQ(Psnr(a, c, mask), 99.0);
}

// A truth sequence panning a texture 1 px a frame: renders with an error they all share score 99,
// one frame off scores what its two changes give.
TEST(ImageMetricsTest, TemporalPsnrCountsOnlyErrorsThatComeAndGo) {
  const cv::Mat texture = Texture(60, 40);
  std::vector<cv::Mat> truths;
  for (int k = 0; k < 5; ++k) truths.push_back(texture(cv::Rect(k, 0, 50, 40)).clone());
  std::vector<cv::Mat> brighter;  // a static error: every frame 6 levels too bright
  for (const cv::Mat& t : truths) {
    cv::Mat b;
    cv::add(t, cv::Scalar::all(6), b);
    brighter.push_back(b);
  }
  EXPECT_EQ(TemporalPsnr(truths, truths), 99.0);
  EXPECT_EQ(TemporalPsnr(brighter, truths), 99.0);  // the blurred texture stays far from 255
  EXPECT_LT(Psnr(brighter[0], truths[0]), 35.0);    // while each frame is off
  // Frame 2 of 5 brighter by 10: its two changes are off by 10 on every pixel; 2 of 4 pairs.
  std::vector<cv::Mat> flicker = truths;  // headers: their pixels are the truths'
  cv::Mat off;
  cv::add(truths[2], cv::Scalar::all(10), off);
  flicker[2] = off;
  EXPECT_NEAR(TemporalPsnr(flicker, truths), 10 * std::log10(255.0 * 255.0 / (100.0 * 2 / 4)), 1e-6);
}

TEST(ImageMetricsTest, SsimIsOneForIdenticalAndDropsWithNoiseAndBlur) {
  const cv::Mat a = Texture(64, 48);
  EXPECT_NEAR(Ssim(a, a), 1.0, 1e-6);
  cv::Mat blurred;
  cv::GaussianBlur(a, blurred, cv::Size(0, 0), 2.0);
  cv::Mat noisy = a.clone();
  cv::Mat noise(a.size(), CV_8UC3);
  cv::randu(noise, cv::Scalar::all(0), cv::Scalar::all(40));
  noisy += noise;
  const double s_blur = Ssim(blurred, a), s_noise = Ssim(noisy, a);
  EXPECT_LT(s_blur, 0.9);
  EXPECT_GT(s_blur, 0.0);
  EXPECT_LT(s_noise, 0.99);
  // A uniform brightness shift hurts SSIM little but PSNR a lot (it measures structure).
  cv::Mat shifted = a + cv::Scalar::all(8);
  EXPECT_GT(Ssim(shifted, a), 0.95);
}

}  // namespace
}  // namespace px::eval
