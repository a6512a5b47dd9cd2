// Local features for per-shot calibration and structure from motion: SIFT (OpenCV 4.6
// features2d; RootSIFT descriptors) or ORB, detected on a grey copy that is downscaled when the
// image is large, with keypoints returned in the input image's pixels.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace px::calib {

struct FeatureOptions {
  enum class Detector {
    kSift,  // scale-invariant, accurate to a few tenths of a pixel; ~60 ms per 640x480 view
    kOrb,   // ~10x faster, coarser keypoints and fewer good matches; for speed experiments
  };
  Detector detector = Detector::kSift;
  // Keep at most this many keypoints (the strongest), [16, 100000].
  int max_features = 2000;
  // Images whose larger side exceeds this are downscaled (area filter) before detection,
  // [64, 16384] pixels. Keypoints are mapped back to the input image.
  int max_image_dim_px = 1600;
  // SIFT contrast threshold, (0, 0.5]: lower finds more keypoints in low-contrast images.
  double sift_contrast_threshold = 0.02;

  Status Validate() const;
};

struct Features {
  int image_width = 0;  // the input image's size
  int image_height = 0;
  std::vector<Eigen::Vector2d> keypoints_px;  // input-image pixels (pixel centres at integers)
  std::vector<float> scales_px;               // keypoint diameter in input-image pixels
  cv::Mat descriptors;                        // one row per keypoint: CV_32F x 128 (RootSIFT) or CV_8U x 32 (ORB)

  int size() const { return static_cast<int>(keypoints_px.size()); }
  bool binary() const { return descriptors.type() == CV_8U; }
};

// Detects features on `image` (8-bit grey or BGR). A blank image gives zero features (not an
// error: callers report it); an empty or non-8-bit image is INVALID_ARGUMENT.
StatusOr<Features> DetectFeatures(const cv::Mat& image, const FeatureOptions& options);

// DetectFeatures on every image, in parallel on OpenCV's thread pool; fails naming the first
// image that cannot be processed.
StatusOr<std::vector<Features>> DetectFeaturesInImages(const std::vector<cv::Mat>& images,
                                                       const FeatureOptions& options);

// Grey-level statistics that explain a view with few features: mean and standard deviation of
// the grey image, and the fractions of pixels at or below 5 and at or above 250.
struct ImageExposure {
  double mean = 0;
  double stddev = 0;
  double dark_fraction = 0;
  double saturated_fraction = 0;
};
ImageExposure MeasureExposure(const cv::Mat& image);
// "blank (grey stddev 0.4)", "overexposed (93% of pixels saturated)", "too dark (...)" or
// "textureless (grey stddev 3.1)": why an image with few features has them, for messages.
std::string DescribeFewFeatures(const ImageExposure& exposure);
// The same, but "" for an image that looks normally exposed and textured (stddev >= 8, less
// than half of it black or saturated): for messages about images that match nothing.
std::string DescribeExposureProblem(const ImageExposure& exposure);

}  // namespace px::calib
