#include "pipeline/depth/plane_warp.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "pipeline/core/check.h"

namespace px::depth {

bool IsTranslation(const Eigen::Matrix3d& h, double* dx, double* dy) {
  constexpr double kTolerance = 1e-9;
  if (std::abs(h(2, 2)) < 1e-12) return false;
  const Eigen::Matrix3d n = h / h(2, 2);
  if (std::abs(n(0, 0) - 1) > kTolerance || std::abs(n(1, 1) - 1) > kTolerance || std::abs(n(0, 1)) > kTolerance ||
      std::abs(n(1, 0)) > kTolerance || std::abs(n(2, 0)) > kTolerance || std::abs(n(2, 1)) > kTolerance) {
    return false;
  }
  *dx = n(0, 2);
  *dy = n(1, 2);
  return true;
}

namespace {

// Keys cubic convolution weights (a = -0.5) for taps at -1, 0, 1, 2 around a fraction t.
void CubicWeights(float t, float w[4]) {
  constexpr float a = -0.5f;
  const auto near = [](float x) { return ((a + 2) * x - (a + 3)) * x * x + 1; };       // |x| <= 1
  const auto far = [](float x) { return ((a * x - 5 * a) * x + 8 * a) * x - 4 * a; };  // 1 < |x| < 2
  w[0] = far(1 + t);
  w[1] = near(t);
  w[2] = near(1 - t);
  w[3] = far(2 - t);
}

// out[x] = w0 in[x] + w1 in[x + 1] + w2 in[x + 2] + w3 in[x + 3]
void Blend4(const float* __restrict in, int count, const float w[4], float* __restrict out) {
  const float w0 = w[0], w1 = w[1], w2 = w[2], w3 = w[3];
  for (int x = 0; x < count; ++x) out[x] = w0 * in[x] + w1 * in[x + 1] + w2 * in[x + 2] + w3 * in[x + 3];
}

void BlendRows(const float* __restrict r0,
               const float* __restrict r1,
               const float* __restrict r2,
               const float* __restrict r3,
               int cols,
               const float w[4],
               float* __restrict out) {
  const float w0 = w[0], w1 = w[1], w2 = w[2], w3 = w[3];
  for (int x = 0; x < cols; ++x) out[x] = w0 * r0[x] + w1 * r1[x] + w2 * r2[x] + w3 * r3[x];
}

}  // namespace

void ShiftCubic(const cv::Mat& src, double dx, double dy, cv::Mat* dst) {
  PX_CHECK(src.type() == CV_32FC1);
  const int rows = src.rows, cols = src.cols;
  dst->create(src.size(), CV_32F);
  const double floor_x = std::floor(dx), floor_y = std::floor(dy);
  const int ix = static_cast<int>(floor_x), iy = static_cast<int>(floor_y);
  float wx[4], wy[4];
  CubicWeights(static_cast<float>(dx - floor_x), wx);
  CubicWeights(static_cast<float>(dy - floor_y), wy);
  // The vertically blended row, padded with |ix| + 3 replicated columns on each side.
  const int pad = std::abs(ix) + 3;
  std::vector<float> blended(cols + 2 * pad);
  for (int y = 0; y < rows; ++y) {
    const float* r[4];
    for (int k = 0; k < 4; ++k) r[k] = src.ptr<float>(std::clamp(y + iy - 1 + k, 0, rows - 1));
    float* b = blended.data() + pad;
    BlendRows(r[0], r[1], r[2], r[3], cols, wy, b);
    for (int i = 1; i <= pad; ++i) {
      b[-i] = b[0];
      b[cols - 1 + i] = b[cols - 1];
    }
    // out[x] uses b[x + ix - 1 .. x + ix + 2]
    Blend4(b + ix - 1, cols, wx, dst->ptr<float>(y));
  }
}

void WarpIntoReference(const cv::Mat& src, const Eigen::Matrix3d& h, cv::Size size, cv::Mat* dst) {
  double dx = 0, dy = 0;
  if (size == src.size() && IsTranslation(h, &dx, &dy)) {
    ShiftCubic(src, dx, dy, dst);
    return;
  }
  const cv::Matx33d m(h(0, 0), h(0, 1), h(0, 2), h(1, 0), h(1, 1), h(1, 2), h(2, 0), h(2, 1), h(2, 2));
  cv::warpPerspective(src, *dst, m, size, cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REPLICATE);
}

void ValidSampleMask(const Eigen::Matrix3d& h, cv::Size src_size, int radius_px, cv::Size size, cv::Mat* mask) {
  mask->create(size, CV_8U);
  mask->setTo(0);
  // Bicubic taps reach 1 pixel before and 2 after the sample.
  const int inset = radius_px + 2;
  const double x0 = inset, y0 = inset;
  const double x1 = src_size.width - 1 - inset, y1 = src_size.height - 1 - inset;
  if (x1 < x0 || y1 < y0) return;
  const Eigen::Matrix3d ref_from_src = h.inverse();
  const Eigen::Vector3d corners[4] = {{x0, y0, 1}, {x1, y0, 1}, {x1, y1, 1}, {x0, y1, 1}};
  constexpr int kShift = 4;  // sub-pixel polygon vertices, 1/16 px
  cv::Point polygon[4];
  bool in_front = true;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d p = ref_from_src * corners[i];
    if (!(p.z() > 1e-12)) {
      in_front = false;
      break;
    }
    // Clamp far outside points so the fixed-point coordinates cannot overflow.
    const double px = std::clamp(p.x() / p.z(), -1e5, 1e5), py = std::clamp(p.y() / p.z(), -1e5, 1e5);
    polygon[i] =
        cv::Point(static_cast<int>(std::lround(px * (1 << kShift))), static_cast<int>(std::lround(py * (1 << kShift))));
  }
  if (in_front) {
    // The image of a rectangle under a homography that keeps it in front is a convex quadrilateral.
    cv::fillConvexPoly(*mask, polygon, 4, cv::Scalar(255), cv::LINE_8, kShift);
    return;
  }
  // The inset rectangle crosses the reference camera's horizon: test every pixel.
  for (int y = 0; y < size.height; ++y) {
    uchar* m = mask->ptr<uchar>(y);
    for (int x = 0; x < size.width; ++x) {
      const Eigen::Vector3d p = h * Eigen::Vector3d(x, y, 1);
      if (p.z() <= 1e-12) continue;
      const double sx = p.x() / p.z(), sy = p.y() / p.z();
      if (sx >= x0 && sx <= x1 && sy >= y0 && sy <= y1) m[x] = 255;
    }
  }
}

}  // namespace px::depth
