#include "eval/render/image_metrics.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "pipeline/core/check.h"

namespace px::eval {

double Psnr(const cv::Mat& image, const cv::Mat& reference, const cv::Mat& mask) {
  PX_CHECK(image.type() == CV_8UC3 && reference.type() == CV_8UC3 && image.size() == reference.size())
      << "Psnr needs two CV_8UC3 images of one size";
  cv::Mat diff;
  cv::absdiff(image, reference, diff);
  diff.convertTo(diff, CV_32FC3);
  diff = diff.mul(diff);
  const double count = mask.empty() ? static_cast<double>(image.total()) : cv::countNonZero(mask);
  if (count <= 0) return 0;
  const cv::Scalar sum = cv::sum(mask.empty() ? diff : diff.setTo(cv::Scalar::all(0), mask == 0));
  const double mse = (sum[0] + sum[1] + sum[2]) / (3 * count);
  return mse <= 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

cv::Mat MaskRegions(const cv::Mat& mask) {
  const cv::Mat square = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3));
  cv::Mat opened;
  cv::morphologyEx(mask, opened, cv::MORPH_OPEN, square);
  return opened & mask;
}

double DoubleImageFraction(const cv::Mat& double_image, cv::Mat* regions) {
  if (double_image.empty()) {
    if (regions != nullptr) regions->release();
    return -1;
  }
  const cv::Mat kept = MaskRegions(double_image);
  if (regions != nullptr) *regions = kept;
  return static_cast<double>(cv::countNonZero(kept)) / static_cast<double>(kept.total());
}

cv::Mat DepthEdgeBand(const cv::Mat& depth_m, int radius_px, double jump) {
  PX_CHECK(depth_m.type() == CV_32F) << "DepthEdgeBand needs a CV_32F depth map";
  cv::Mat log_depth;
  cv::max(depth_m, 1e-6, log_depth);
  cv::log(log_depth, log_depth);
  cv::Mat dx, dy;
  cv::Sobel(log_depth, dx, CV_32F, 1, 0, 1);
  cv::Sobel(log_depth, dy, CV_32F, 0, 1, 1);
  cv::Mat band = (cv::abs(dx) > jump) | (cv::abs(dy) > jump);
  const int size = 2 * radius_px + 1;
  cv::dilate(band, band, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(size, size)));
  return band;
}

double TemporalPsnr(const std::vector<cv::Mat>& renders, const std::vector<cv::Mat>& truths) {
  PX_CHECK(renders.size() == truths.size() && renders.size() >= 2)
      << "TemporalPsnr needs as many truths as renders, >= 2";
  // (R[k+1] - R[k]) - (T[k+1] - T[k]) = E[k+1] - E[k], E = R - T each frame's signed error.
  std::vector<cv::Mat> errors;
  for (size_t k = 0; k < renders.size(); ++k) {
    PX_CHECK(renders[k].type() == CV_8UC3 && truths[k].type() == CV_8UC3 && renders[k].size() == renders[0].size() &&
             truths[k].size() == renders[0].size())
        << "TemporalPsnr needs CV_8UC3 frames of one size";
    cv::Mat error;
    cv::subtract(renders[k], truths[k], error, cv::noArray(), CV_32FC3);
    errors.push_back(error);
  }
  double sum = 0, count = 0;
  for (size_t k = 0; k + 1 < errors.size(); ++k) {
    const cv::Mat change = errors[k + 1] - errors[k];
    const cv::Scalar squares = cv::sum(change.mul(change));
    sum += squares[0] + squares[1] + squares[2];
    count += 3.0 * static_cast<double>(change.total());
  }
  const double mse = sum / count;
  return mse <= 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

double Ssim(const cv::Mat& image, const cv::Mat& reference, const cv::Mat& mask) {
  PX_CHECK(image.type() == CV_8UC3 && reference.type() == CV_8UC3 && image.size() == reference.size())
      << "Ssim needs two CV_8UC3 images of one size";
  constexpr double kC1 = (0.01 * 255) * (0.01 * 255), kC2 = (0.03 * 255) * (0.03 * 255);
  const cv::Size window(11, 11);
  const double sigma = 1.5;
  cv::Mat a, b;
  image.convertTo(a, CV_32FC3);
  reference.convertTo(b, CV_32FC3);
  cv::Mat mu_a, mu_b, aa, bb, ab;
  cv::GaussianBlur(a, mu_a, window, sigma);
  cv::GaussianBlur(b, mu_b, window, sigma);
  cv::GaussianBlur(a.mul(a), aa, window, sigma);
  cv::GaussianBlur(b.mul(b), bb, window, sigma);
  cv::GaussianBlur(a.mul(b), ab, window, sigma);
  const cv::Mat mu_aa = mu_a.mul(mu_a), mu_bb = mu_b.mul(mu_b), mu_ab = mu_a.mul(mu_b);
  const cv::Mat var_a = aa - mu_aa, var_b = bb - mu_bb, cov = ab - mu_ab;
  cv::Mat numerator = (2 * mu_ab + kC1).mul(2 * cov + kC2);
  cv::Mat denominator = (mu_aa + mu_bb + kC1).mul(var_a + var_b + kC2);
  cv::Mat ssim_map;
  cv::divide(numerator, denominator, ssim_map);
  const double count = mask.empty() ? static_cast<double>(image.total()) : cv::countNonZero(mask);
  if (count <= 0) return 0;
  const cv::Scalar mean = mask.empty() ? cv::sum(ssim_map) : cv::sum(ssim_map.setTo(cv::Scalar::all(0), mask == 0));
  return (mean[0] + mean[1] + mean[2]) / (3 * count);
}

}  // namespace px::eval
