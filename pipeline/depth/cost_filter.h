// Edge-aware aggregation of one cost slice with a guided filter (He et al. 2010) guided by the
// reference image: cost-volume filtering (Hosni et al. 2013). It spreads evidence from textured
// pixels into weakly textured ones of the same surface without crossing intensity edges.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace px::depth {

// Statistics of the guide (grey reference, CV_32F in [0, 1]) computed once per reference view.
struct CostFilterGuide {
  int radius_px = 0;
  float eps = 0;
  cv::Mat guide;         // I
  cv::Mat mean;          // box mean of I
  cv::Mat inv_variance;  // 1 / (box variance of I + eps)
};

// eps (grey levels^2 in [0, 1] units) sets what counts as an edge: windows whose variance is well
// above eps keep their own costs, flatter ones are averaged.
CostFilterGuide PrepareCostFilterGuide(const cv::Mat& gray, int radius_px, double eps);

struct CostFilterWorkspace {
  std::vector<float> scratch;
  cv::Mat product, mean_cost, mean_product, a, b;
  cv::Mat weight, weighted_guide, weighted_guide2, mean_weight, mean_guide, mean_guide2;
};

// Replaces `cost` (CV_32F, the guide's size) by its guided-filtered version, in place. Pixels at
// kNoDataCost (no neighbour sampled them) do not take part: the window statistics use only pixels
// with data, so a border strip without samples does not bias its neighbours (it receives their
// filtered costs). Pixels whose windows all lack data stay at kNoDataCost.
void FilterCostSlice(const CostFilterGuide& guide, CostFilterWorkspace* workspace, cv::Mat* cost);

}  // namespace px::depth
