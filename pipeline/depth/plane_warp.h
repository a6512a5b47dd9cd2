// Warping a neighbour view into the reference view for one plane of the sweep, and the region
// where that warp has real samples.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace px::depth {

// dst(x) = src(H x) with replicated borders; H maps reference pixels to source pixels; src and dst
// are CV_32F. A pure translation (parallel cameras with equal intrinsics and no forward offset:
// the usual lattice, and the HCI light fields) takes a fast separable bicubic path with constant
// weights; anything else goes through cv::warpPerspective (bilinear).
void WarpIntoReference(const cv::Mat& src, const Eigen::Matrix3d& h, cv::Size size, cv::Mat* dst);

// dst(x, y) = src(x + dx, y + dy) by Keys bicubic interpolation (a = -0.5), borders replicated.
// CV_32F. Bicubic rather than bilinear: bilinear blurs most at half-pixel shifts, which pulls the
// matching cost's minimum towards whole-pixel disparities ("pixel locking"); on a synthetic
// plane this cut the disparity bias from 0.05 px to 0.02 px.
void ShiftCubic(const cv::Mat& src, double dx, double dy, cv::Mat* dst);

// True (with the shift) when H is a translation to within 1e-9 in its linear part.
bool IsTranslation(const Eigen::Matrix3d& h, double* dx, double* dy);

// 255 where the whole matching window around H x, with its interpolation footprint, lies inside
// the source image (approximately: the source rectangle inset by radius + 2, mapped back into
// the reference view), else 0.
void ValidSampleMask(const Eigen::Matrix3d& h, cv::Size src_size, int radius_px, cv::Size size, cv::Mat* mask);

}  // namespace px::depth
