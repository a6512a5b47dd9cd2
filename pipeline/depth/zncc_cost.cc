#include "pipeline/depth/zncc_cost.h"

#include <algorithm>
#include <cmath>

#include "pipeline/core/check.h"
#include "pipeline/depth/box_mean.h"

namespace px::depth {
namespace {

// acc[x] += add[x] - sub[x] (separate function so __restrict is honoured and the loop vectorises).
void SlideColumn(const float* __restrict add, const float* __restrict sub, int cols, float* __restrict acc) {
  for (int x = 0; x < cols; ++x) acc[x] += add[x] - sub[x];
}

// 1 - ZNCC for one row from the window sums (means once scaled by inv_area).
void ZnccRow(const float* __restrict sum_w,
             const float* __restrict sum_ww,
             const float* __restrict sum_gw,
             const float* __restrict mean_g,
             const float* __restrict inv_g,
             int cols,
             float inv_area,
             float min_variance,
             float* __restrict cost) {
  for (int x = 0; x < cols; ++x) {
    const float mean_w = sum_w[x] * inv_area;
    const float variance_w = std::max(sum_ww[x] * inv_area - mean_w * mean_w, min_variance);
    const float covariance = sum_gw[x] * inv_area - mean_g[x] * mean_w;
    // inv_g == 0 (textureless reference) gives ncc 0, the neutral cost. Clamping the cost (not
    // ncc) to [0, 2] is the same and keeps the loop branch-free for the vectoriser.
    const float ncc = covariance * inv_g[x] / std::sqrt(variance_w);
    cost[x] = std::clamp(1.0f - ncc, 0.0f, 2.0f);
  }
}

void MaskRow(const uchar* __restrict valid, int cols, float* __restrict cost) {
  for (int x = 0; x < cols; ++x) cost[x] = valid[x] != 0 ? cost[x] : kInvalidCost;
}

void Products(
    const float* __restrict w, const float* __restrict g, int cols, float* __restrict ww, float* __restrict gw) {
  for (int x = 0; x < cols; ++x) {
    ww[x] = w[x] * w[x];
    gw[x] = g[x] * w[x];
  }
}

}  // namespace

ReferenceWindows PrepareReferenceWindows(const cv::Mat& gray, int radius_px, double min_texture_stddev) {
  PX_CHECK(gray.type() == CV_32FC1) << "reference must be CV_32F grey";
  ReferenceWindows ref;
  ref.radius_px = radius_px;
  ref.min_variance = std::max(static_cast<float>(min_texture_stddev * min_texture_stddev), 1e-7f);
  ref.gray = gray;
  cv::Mat squared, mean_squared;
  cv::multiply(gray, gray, squared);
  std::vector<float> scratch;
  BoxMean(gray, radius_px, &scratch, &ref.mean);
  BoxMean(squared, radius_px, &scratch, &mean_squared);
  ref.inv_stddev.create(gray.size(), CV_32F);
  for (int y = 0; y < gray.rows; ++y) {
    const float* m = ref.mean.ptr<float>(y);
    const float* m2 = mean_squared.ptr<float>(y);
    float* inv = ref.inv_stddev.ptr<float>(y);
    for (int x = 0; x < gray.cols; ++x) {
      const float variance = m2[x] - m[x] * m[x];
      inv[x] = variance > ref.min_variance ? 1.0f / std::sqrt(variance) : 0.0f;
    }
  }
  return ref;
}

void ComputeZnccCost(
    const ReferenceWindows& ref, const cv::Mat& warped, const cv::Mat& valid, ZnccWorkspace* workspace, cv::Mat* cost) {
  PX_CHECK(warped.type() == CV_32FC1 && warped.size() == ref.gray.size()) << "warped image must match the reference";
  const int rows = warped.rows, cols = warped.cols, r = ref.radius_px;
  workspace->row_sums.create(3 * rows, cols, CV_32F);
  workspace->padded.resize(cols + 2 * r);
  workspace->column_sums.assign(3 * cols, 0.0f);
  std::vector<float>& products = workspace->products;
  products.resize(2 * cols);
  // Row sums of w, w^2 and ref * w, stacked as three row blocks.
  for (int y = 0; y < rows; ++y) {
    float* ww = products.data();
    float* gw = products.data() + cols;
    Products(warped.ptr<float>(y), ref.gray.ptr<float>(y), cols, ww, gw);
    RowWindowSum(warped.ptr<float>(y), cols, r, workspace->padded.data(), workspace->row_sums.ptr<float>(y));
    RowWindowSum(ww, cols, r, workspace->padded.data(), workspace->row_sums.ptr<float>(rows + y));
    RowWindowSum(gw, cols, r, workspace->padded.data(), workspace->row_sums.ptr<float>(2 * rows + y));
  }
  // Column sums: the first window directly, then slide down one row at a time.
  float* sums[3] = {
      workspace->column_sums.data(), workspace->column_sums.data() + cols, workspace->column_sums.data() + 2 * cols};
  for (int dy = -r; dy <= r; ++dy) {
    const int row = ReflectIndex(dy, rows);
    for (int q = 0; q < 3; ++q) AddRowTo(workspace->row_sums.ptr<float>(q * rows + row), cols, sums[q]);
  }
  cost->create(warped.size(), CV_32F);
  const float inv_area = 1.0f / static_cast<float>((2 * r + 1) * (2 * r + 1));
  for (int y = 0; y < rows; ++y) {
    if (y > 0) {
      const int add = ReflectIndex(y + r, rows), sub = ReflectIndex(y - r - 1, rows);
      for (int q = 0; q < 3; ++q) {
        SlideColumn(workspace->row_sums.ptr<float>(q * rows + add),
                    workspace->row_sums.ptr<float>(q * rows + sub),
                    cols,
                    sums[q]);
      }
    }
    float* c = cost->ptr<float>(y);
    ZnccRow(sums[0],
            sums[1],
            sums[2],
            ref.mean.ptr<float>(y),
            ref.inv_stddev.ptr<float>(y),
            cols,
            inv_area,
            ref.min_variance,
            c);
    if (!valid.empty()) MaskRow(valid.ptr<uchar>(y), cols, c);
  }
}

}  // namespace px::depth
