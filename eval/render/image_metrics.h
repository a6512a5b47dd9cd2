// Image quality against a reference: PSNR and SSIM (Wang et al. 2004: 11x11 Gaussian window,
// sigma 1.5, K1 0.01, K2 0.03 on the 0..255 scale, averaged over the BGR channels), over the
// whole image or the pixels of a mask.
#pragma once

#include <opencv2/core.hpp>

namespace px::eval {

// PSNR in dB of CV_8UC3 `image` against `reference` (same size) where `mask` (CV_8U, may be empty)
// is non-zero; 99 when they are identical there.
double Psnr(const cv::Mat& image, const cv::Mat& reference, const cv::Mat& mask = cv::Mat());

// Mean SSIM in [-1, 1] of CV_8UC3 images of the same size, over the mask's pixels (all when empty).
double Ssim(const cv::Mat& image, const cv::Mat& reference, const cv::Mat& mask = cv::Mat());

}  // namespace px::eval
