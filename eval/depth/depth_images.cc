#include "eval/depth/depth_images.h"

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace px::eval {
namespace {

namespace fs = std::filesystem;

cv::Mat ColourMap(const cv::Mat& values, double lo, double hi) {
  cv::Mat scaled(values.size(), CV_8U), mask(values.size(), CV_8U);
  for (int y = 0; y < values.rows; ++y) {
    for (int x = 0; x < values.cols; ++x) {
      const float v = values.at<float>(y, x);
      const bool ok = std::isfinite(v);
      mask.at<uchar>(y, x) = ok ? 255 : 0;
      scaled.at<uchar>(y, x) = ok ? cv::saturate_cast<uchar>(255.0 * (v - lo) / (hi - lo)) : 0;
    }
  }
  cv::Mat coloured;
  cv::applyColorMap(scaled, coloured, cv::COLORMAP_TURBO);
  coloured.setTo(cv::Scalar::all(0), mask == 0);
  return coloured;
}

Status Write(const fs::path& path, const cv::Mat& image) {
  if (!cv::imwrite(path.string(), image)) return UnavailableError(path.string() + ": cannot write");
  return OkStatus();
}

}  // namespace

std::string FileStem(const std::string& name) {
  std::string stem;
  for (char c : name) stem += std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' ? c : '_';
  return stem;
}

Status WriteDepthImages(const fs::path& dir,
                        const std::string& stem,
                        const cv::Mat& estimate,
                        const cv::Mat& truth,
                        double good,
                        double bad) {
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) return UnavailableError(dir.string() + ": cannot create (" + error.message() + ")");
  double lo = 0, hi = 1;
  cv::Mat finite_mask = truth == truth;  // false for NaN
  cv::minMaxLoc(truth, &lo, &hi, nullptr, nullptr, finite_mask);
  if (!(hi > lo)) hi = lo + 1;
  cv::Mat errors(truth.size(), CV_8UC3, cv::Scalar::all(0));
  for (int y = 0; y < truth.rows; ++y) {
    for (int x = 0; x < truth.cols; ++x) {
      const float t = truth.at<float>(y, x), e = estimate.at<float>(y, x);
      if (!std::isfinite(t)) continue;
      const double diff = std::isfinite(e) ? std::abs(e - t) : 1e9;
      errors.at<cv::Vec3b>(y, x) = diff <= good  ? cv::Vec3b(128, 128, 128)
                                   : diff <= bad ? cv::Vec3b(0, 220, 255)
                                                 : cv::Vec3b(0, 0, 255);
    }
  }
  PX_RETURN_IF_ERROR(Write(dir / (stem + "_estimate.png"), ColourMap(estimate, lo, hi)));
  PX_RETURN_IF_ERROR(Write(dir / (stem + "_truth.png"), ColourMap(truth, lo, hi)));
  return Write(dir / (stem + "_error.png"), errors);
}

}  // namespace px::eval
