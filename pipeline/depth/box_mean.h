// Box (moving average) filters over (2r+1)^2 windows with reflected borders, written as plain
// loops the compiler vectorises: direct sums along rows, running sums down columns.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace px::depth {

// acc[x] += row[x] for x < cols: one step of the running sums down columns.
inline void AddRowTo(const float* __restrict row, int cols, float* __restrict acc) {
  for (int x = 0; x < cols; ++x) acc[x] += row[x];
}

// OpenCV's BORDER_REFLECT (fedcba|abcdef|fedcba) for any offset i into [0, n).
int ReflectIndex(int i, int n);

// dst[x] = src[x - r] + ... + src[x + r] along one row, borders reflected. `padded` must hold
// cols + 2r floats.
void RowWindowSum(const float* src, int cols, int radius, float* padded, float* dst);

// dst = box mean of src (CV_32F). `scratch` is reused between calls.
void BoxMean(const cv::Mat& src, int radius, std::vector<float>* scratch, cv::Mat* dst);

}  // namespace px::depth
