#include "eval/render/image_metrics.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

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
