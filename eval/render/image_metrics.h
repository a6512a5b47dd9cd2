// Image quality against a reference: PSNR and SSIM (Wang et al. 2004: 11x11 Gaussian window,
// sigma 1.5, K1 0.01, K2 0.03 on the 0..255 scale, averaged over the BGR channels), over the
// whole image or the pixels of a mask.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace px::eval {

// PSNR in dB of CV_8UC3 `image` against `reference` (same size) where `mask` (CV_8U, may be empty)
// is non-zero; 99 when they are identical there.
double Psnr(const cv::Mat& image, const cv::Mat& reference, const cv::Mat& mask = cv::Mat());

// Temporal steadiness of a rendered sequence against its truth (CV_8UC3 frames, one size, as many
// truths as renders, at least two): PSNR of each frame-to-frame change against the truth's
// change, (R[k+1] - R[k]) - (T[k+1] - T[k]), over all pixels and consecutive pairs. An error the
// frames share (a static blur, a shifted colour) does not count; one that comes and goes (a view
// handed over, a flickering edge) does. 99 when every change matches.
double TemporalPsnr(const std::vector<cv::Mat>& renders, const std::vector<cv::Mat>& truths);

// The pixels (CV_8U, 255) within `radius_px` of a jump of more than `jump` in log depth (about
// that fraction) between neighbouring pixels of `depth_m` (CV_32F, z): where silhouettes are.
cv::Mat DepthEdgeBand(const cv::Mat& depth_m, int radius_px = 3, double jump = 0.05);

// `mask` (CV_8U) less what a 3x3 opening removes: regions, not the single pixels or one-pixel lines
// that resampling leaves along strong edges.
cv::Mat MaskRegions(const cv::Mat& mask);

// The share of the frame that `double_image` (FrameRender::double_image) marks in regions
// (MaskRegions): a second image, not a pixel of resampling noise. -1 when it is empty (the back
// end did not measure it). `regions` (may be null) receives them (CV_8U, 255).
double DoubleImageFraction(const cv::Mat& double_image, cv::Mat* regions = nullptr);

// Mean SSIM in [-1, 1] of CV_8UC3 images of the same size, over the mask's pixels (all when empty).
double Ssim(const cv::Mat& image, const cv::Mat& reference, const cv::Mat& mask = cv::Mat());

}  // namespace px::eval
