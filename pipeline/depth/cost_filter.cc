#include "pipeline/depth/cost_filter.h"

#include <algorithm>

#include "pipeline/core/check.h"
#include "pipeline/depth/box_mean.h"
#include "pipeline/depth/zncc_cost.h"

namespace px::depth {
namespace {

// a = cov(I, p) / (var(I) + eps), b = mean(p) - a mean(I)
void Coefficients(const float* __restrict mean_i,
                  const float* __restrict inv_variance,
                  const float* __restrict mean_p,
                  const float* __restrict mean_ip,
                  int n,
                  float* __restrict a,
                  float* __restrict b) {
  for (int i = 0; i < n; ++i) {
    const float slope = (mean_ip[i] - mean_i[i] * mean_p[i]) * inv_variance[i];
    a[i] = slope;
    b[i] = mean_p[i] - slope * mean_i[i];
  }
}

// weight = 1 where the cost has data, else 0; the cost is zeroed there. Returns the number of
// pixels without data.
int MaskNoData(int n, float* __restrict cost, float* __restrict weight) {
  int missing = 0;
  for (int i = 0; i < n; ++i) {
    const bool has_data = cost[i] < kNoDataCost;
    missing += has_data ? 0 : 1;
    weight[i] = has_data ? 1.0f : 0.0f;
    cost[i] = has_data ? cost[i] : 0.0f;
  }
  return missing;
}

void Products(const float* __restrict guide,
              const float* __restrict cost,
              const float* __restrict weight,
              int n,
              float* __restrict guide_cost,
              float* __restrict weighted_guide,
              float* __restrict weighted_guide2) {
  for (int i = 0; i < n; ++i) {
    guide_cost[i] = guide[i] * cost[i];
    weighted_guide[i] = weight[i] * guide[i];
    weighted_guide2[i] = weight[i] * guide[i] * guide[i];
  }
}

// The guided filter's coefficients from statistics over the pixels with data only: each sum is
// divided by the window's data weight. Windows without data get a = 0, b = kNoDataCost.
void MaskedCoefficients(const float* __restrict sum_w,
                        const float* __restrict sum_wi,
                        const float* __restrict sum_wii,
                        const float* __restrict sum_p,
                        const float* __restrict sum_ip,
                        int n,
                        float eps,
                        float* __restrict a,
                        float* __restrict b) {
  for (int i = 0; i < n; ++i) {
    const float w = sum_w[i];
    const bool any = w > 1e-6f;
    const float inv = 1.0f / std::max(w, 1e-6f);
    const float mean_i = sum_wi[i] * inv, mean_p = sum_p[i] * inv;
    const float variance = std::max(sum_wii[i] * inv - mean_i * mean_i, 0.0f);
    const float slope = (sum_ip[i] * inv - mean_i * mean_p) / (variance + eps);
    a[i] = any ? slope : 0.0f;
    b[i] = any ? mean_p - slope * mean_i : kNoDataCost;
  }
}

void Combine(const float* __restrict mean_a,
             const float* __restrict mean_b,
             const float* __restrict guide,
             int n,
             float* __restrict out) {
  for (int i = 0; i < n; ++i) out[i] = mean_a[i] * guide[i] + mean_b[i];
}

}  // namespace

CostFilterGuide PrepareCostFilterGuide(const cv::Mat& gray, int radius_px, double eps) {
  PX_CHECK(gray.type() == CV_32FC1 && gray.isContinuous());
  CostFilterGuide guide;
  guide.radius_px = radius_px;
  guide.eps = static_cast<float>(eps);
  guide.guide = gray;
  std::vector<float> scratch;
  cv::Mat squared, mean_squared;
  cv::multiply(gray, gray, squared);
  BoxMean(gray, radius_px, &scratch, &guide.mean);
  BoxMean(squared, radius_px, &scratch, &mean_squared);
  guide.inv_variance = 1.0 / (mean_squared - guide.mean.mul(guide.mean) + eps);
  return guide;
}

void FilterCostSlice(const CostFilterGuide& guide, CostFilterWorkspace* workspace, cv::Mat* cost) {
  PX_CHECK(cost->type() == CV_32FC1 && cost->size() == guide.guide.size() && cost->isContinuous());
  const int n = static_cast<int>(cost->total());
  const int r = guide.radius_px;
  CostFilterWorkspace& w = *workspace;
  for (cv::Mat* m : {&w.weight, &w.product, &w.weighted_guide, &w.weighted_guide2, &w.a, &w.b}) {
    m->create(cost->size(), CV_32F);
  }
  const float* i_ptr = guide.guide.ptr<float>();
  float* p_ptr = cost->ptr<float>();
  const int missing = MaskNoData(n, p_ptr, w.weight.ptr<float>());
  Products(i_ptr,
           p_ptr,
           w.weight.ptr<float>(),
           n,
           w.product.ptr<float>(),
           w.weighted_guide.ptr<float>(),
           w.weighted_guide2.ptr<float>());
  BoxMean(*cost, r, &w.scratch, &w.mean_cost);
  BoxMean(w.product, r, &w.scratch, &w.mean_product);
  if (missing == 0) {
    Coefficients(guide.mean.ptr<float>(),
                 guide.inv_variance.ptr<float>(),
                 w.mean_cost.ptr<float>(),
                 w.mean_product.ptr<float>(),
                 n,
                 w.a.ptr<float>(),
                 w.b.ptr<float>());
  } else {
    // Near the borders no neighbour samples some planes: statistics over the sampled pixels only,
    // so the missing ones neither pull costs up nor skew the guide's statistics.
    BoxMean(w.weight, r, &w.scratch, &w.mean_weight);
    BoxMean(w.weighted_guide, r, &w.scratch, &w.mean_guide);
    BoxMean(w.weighted_guide2, r, &w.scratch, &w.mean_guide2);
    MaskedCoefficients(w.mean_weight.ptr<float>(),
                       w.mean_guide.ptr<float>(),
                       w.mean_guide2.ptr<float>(),
                       w.mean_cost.ptr<float>(),
                       w.mean_product.ptr<float>(),
                       n,
                       guide.eps,
                       w.a.ptr<float>(),
                       w.b.ptr<float>());
  }
  BoxMean(w.a, r, &w.scratch, &w.mean_cost);     // reuse as mean of a
  BoxMean(w.b, r, &w.scratch, &w.mean_product);  // reuse as mean of b
  Combine(w.mean_cost.ptr<float>(), w.mean_product.ptr<float>(), i_ptr, n, p_ptr);
}

}  // namespace px::depth
