#include "pipeline/calib/features.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core/utility.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

namespace px::calib {
namespace {

cv::Mat GreyOf(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return grey;
}

// RootSIFT (Arandjelovic and Zisserman 2012): L1-normalise, then square root. Euclidean
// distance between RootSIFT vectors is the Hellinger kernel on SIFT, which matches better.
void ToRootSift(cv::Mat* descriptors) {
  for (int r = 0; r < descriptors->rows; ++r) {
    float* row = descriptors->ptr<float>(r);
    double sum = 0;
    for (int c = 0; c < descriptors->cols; ++c) sum += std::abs(row[c]);
    const double scale = sum > 0 ? 1.0 / sum : 0.0;
    for (int c = 0; c < descriptors->cols; ++c) row[c] = static_cast<float>(std::sqrt(std::abs(row[c]) * scale));
  }
}

}  // namespace

Status FeatureOptions::Validate() const {
  if (detector != Detector::kSift && detector != Detector::kOrb) {
    return InvalidArgumentError("feature options: detector = " + std::to_string(static_cast<int>(detector)) +
                                " is not SIFT (0) or ORB (1)");
  }
  if (max_features < 16 || max_features > 100000) {
    return InvalidArgumentError("feature options: max_features = " + std::to_string(max_features) +
                                " is outside [16, 100000]");
  }
  if (max_image_dim_px < 64 || max_image_dim_px > 16384) {
    return InvalidArgumentError("feature options: max_image_dim_px = " + std::to_string(max_image_dim_px) +
                                " is outside [64, 16384]");
  }
  if (!(sift_contrast_threshold > 0 && sift_contrast_threshold <= 0.5)) {
    return InvalidArgumentError("feature options: sift_contrast_threshold = " +
                                std::to_string(sift_contrast_threshold) + " is outside (0, 0.5]");
  }
  return OkStatus();
}

StatusOr<Features> DetectFeatures(const cv::Mat& image, const FeatureOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  if (image.empty()) return InvalidArgumentError("feature detection: the image is empty");
  if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3 && image.channels() != 4)) {
    return InvalidArgumentError("feature detection: the image has " + std::to_string(image.channels()) +
                                " channels of depth " + std::to_string(image.depth()) + ", want 8-bit grey or BGR");
  }
  cv::Mat grey = GreyOf(image);
  const int larger = std::max(grey.cols, grey.rows);
  double scale = 1.0;  // detection image pixels per input pixel
  if (larger > options.max_image_dim_px) {
    scale = static_cast<double>(options.max_image_dim_px) / larger;
    cv::Mat small;
    cv::resize(grey, small, cv::Size(), scale, scale, cv::INTER_AREA);
    grey = small;
  }

  std::vector<cv::KeyPoint> keypoints;
  Features features;
  features.image_width = image.cols;
  features.image_height = image.rows;
  if (options.detector == FeatureOptions::Detector::kSift) {
    cv::Ptr<cv::SIFT> sift = cv::SIFT::create(options.max_features, 3, options.sift_contrast_threshold);
    sift->detectAndCompute(grey, cv::noArray(), keypoints, features.descriptors);
    // SIFT may return a few more than asked (ties) and duplicates with several orientations.
    if (static_cast<int>(keypoints.size()) > options.max_features) {
      keypoints.resize(options.max_features);
      features.descriptors = features.descriptors.rowRange(0, options.max_features).clone();
    }
    if (!features.descriptors.empty()) ToRootSift(&features.descriptors);
  } else {
    cv::Ptr<cv::ORB> orb = cv::ORB::create(options.max_features);
    orb->detectAndCompute(grey, cv::noArray(), keypoints, features.descriptors);
  }
  features.keypoints_px.reserve(keypoints.size());
  features.scales_px.reserve(keypoints.size());
  for (const cv::KeyPoint& keypoint : keypoints) {
    // Pixel centres sit at integers in both images: x_in = (x_small + 0.5) / scale - 0.5.
    features.keypoints_px.emplace_back((keypoint.pt.x + 0.5) / scale - 0.5, (keypoint.pt.y + 0.5) / scale - 0.5);
    features.scales_px.push_back(static_cast<float>(keypoint.size / scale));
  }
  if (features.descriptors.empty()) {
    features.descriptors = cv::Mat(0,
                                   options.detector == FeatureOptions::Detector::kSift ? 128 : 32,
                                   options.detector == FeatureOptions::Detector::kSift ? CV_32F : CV_8U);
  }
  return features;
}

StatusOr<std::vector<Features>> DetectFeaturesInImages(const std::vector<cv::Mat>& images,
                                                       const FeatureOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  std::vector<StatusOr<Features>> detected(images.size(), InternalError("not run"));
  cv::parallel_for_(cv::Range(0, static_cast<int>(images.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) detected[i] = DetectFeatures(images[i], options);
  });
  std::vector<Features> features;
  features.reserve(images.size());
  for (size_t i = 0; i < detected.size(); ++i) {
    if (!detected[i].ok()) return detected[i].status().WithContext("view " + std::to_string(i));
    features.push_back(std::move(detected[i]).value());
  }
  return features;
}

ImageExposure MeasureExposure(const cv::Mat& image) {
  ImageExposure exposure;
  if (image.empty()) return exposure;
  const cv::Mat grey = GreyOf(image);
  cv::Scalar mean, stddev;
  cv::meanStdDev(grey, mean, stddev);
  exposure.mean = mean[0];
  exposure.stddev = stddev[0];
  const double total = static_cast<double>(grey.total());
  exposure.dark_fraction = cv::countNonZero(grey <= 5) / total;
  exposure.saturated_fraction = cv::countNonZero(grey >= 250) / total;
  return exposure;
}

std::string DescribeFewFeatures(const ImageExposure& exposure) {
  char text[128];
  if (exposure.stddev < 1.0) {
    std::snprintf(text, sizeof(text), "blank (grey mean %.0f, stddev %.2f)", exposure.mean, exposure.stddev);
  } else if (exposure.saturated_fraction > 0.5) {
    std::snprintf(text, sizeof(text), "overexposed (%.0f%% of pixels saturated)", 100 * exposure.saturated_fraction);
  } else if (exposure.dark_fraction > 0.5) {
    std::snprintf(text, sizeof(text), "too dark (%.0f%% of pixels black)", 100 * exposure.dark_fraction);
  } else {
    std::snprintf(text, sizeof(text), "textureless or blurred (grey stddev %.1f)", exposure.stddev);
  }
  return text;
}

std::string DescribeExposureProblem(const ImageExposure& exposure) {
  if (exposure.stddev >= 8.0 && exposure.saturated_fraction <= 0.5 && exposure.dark_fraction <= 0.5) return "";
  return DescribeFewFeatures(exposure);
}

}  // namespace px::calib
