#include "pipeline/depth/box_mean.h"

#include <algorithm>

#include "pipeline/core/check.h"

namespace px::depth {
namespace {

// out[x] = in[x] + ... + in[x + 2R]: a fixed window length lets the compiler keep the sum in
// registers and vectorise across x.
template <int R>
void SumWindows(const float* __restrict in, int cols, float* __restrict out) {
  for (int x = 0; x < cols; ++x) {
    float sum = in[x];
    for (int k = 1; k <= 2 * R; ++k) sum += in[x + k];
    out[x] = sum;
  }
}

void SumWindowsAnyRadius(const float* __restrict in, int cols, int radius, float* __restrict out) {
  for (int x = 0; x < cols; ++x) {
    float sum = in[x];
    for (int k = 1; k <= 2 * radius; ++k) sum += in[x + k];
    out[x] = sum;
  }
}

void SlideAndScale(const float* __restrict add,
                   const float* __restrict sub,
                   int cols,
                   float scale,
                   float* __restrict acc,
                   float* __restrict out) {
  for (int x = 0; x < cols; ++x) {
    acc[x] += add[x] - sub[x];
    out[x] = acc[x] * scale;
  }
}

void Scale(const float* __restrict acc, int cols, float scale, float* __restrict out) {
  for (int x = 0; x < cols; ++x) out[x] = acc[x] * scale;
}

}  // namespace

int ReflectIndex(int i, int n) {
  if (n == 1) return 0;
  while (i < 0 || i >= n) i = i < 0 ? -i - 1 : 2 * n - i - 1;
  return i;
}

void RowWindowSum(const float* src, int cols, int radius, float* padded, float* dst) {
  for (int i = 0; i < radius; ++i) {
    padded[i] = src[ReflectIndex(i - radius, cols)];
    padded[cols + radius + i] = src[ReflectIndex(cols + i, cols)];
  }
  std::copy(src, src + cols, padded + radius);
  switch (radius) {
    case 1:
      SumWindows<1>(padded, cols, dst);
      break;
    case 2:
      SumWindows<2>(padded, cols, dst);
      break;
    case 3:
      SumWindows<3>(padded, cols, dst);
      break;
    case 4:
      SumWindows<4>(padded, cols, dst);
      break;
    case 5:
      SumWindows<5>(padded, cols, dst);
      break;
    case 6:
      SumWindows<6>(padded, cols, dst);
      break;
    case 7:
      SumWindows<7>(padded, cols, dst);
      break;
    case 8:
      SumWindows<8>(padded, cols, dst);
      break;
    default:
      SumWindowsAnyRadius(padded, cols, radius, dst);
      break;
  }
}

void BoxMean(const cv::Mat& src, int radius, std::vector<float>* scratch, cv::Mat* dst) {
  PX_CHECK(src.type() == CV_32FC1);
  const int rows = src.rows, cols = src.cols, r = radius;
  // Row sums of every row, then one running column sum; padded row and accumulator after them.
  scratch->resize(static_cast<size_t>(rows) * cols + (cols + 2 * r) + cols);
  float* row_sums = scratch->data();
  float* padded = row_sums + static_cast<size_t>(rows) * cols;
  float* column = padded + cols + 2 * r;
  auto row = [&](int y) { return row_sums + static_cast<size_t>(y) * cols; };
  for (int y = 0; y < rows; ++y) RowWindowSum(src.ptr<float>(y), cols, r, padded, row(y));
  dst->create(src.size(), CV_32F);
  const float inv_area = 1.0f / static_cast<float>((2 * r + 1) * (2 * r + 1));
  std::fill_n(column, cols, 0.0f);
  for (int dy = -r; dy <= r; ++dy) AddRowTo(row(ReflectIndex(dy, rows)), cols, column);
  Scale(column, cols, inv_area, dst->ptr<float>(0));
  for (int y = 1; y < rows; ++y) {
    SlideAndScale(
        row(ReflectIndex(y + r, rows)), row(ReflectIndex(y - r - 1, rows)), cols, inv_area, column, dst->ptr<float>(y));
  }
}

}  // namespace px::depth
