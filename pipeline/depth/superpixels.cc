#include "pipeline/depth/superpixels.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc/slic.hpp>

#include "pipeline/core/check.h"

namespace px::depth {
namespace {

// Renumbers labels to 0 .. n - 1 in order of first appearance; returns n.
int CompactLabels(cv::Mat* labels) {
  double max_label = 0;
  cv::minMaxLoc(*labels, nullptr, &max_label);
  std::vector<int> remap(static_cast<size_t>(max_label) + 1, -1);
  int next = 0;
  for (int y = 0; y < labels->rows; ++y) {
    int* l = labels->ptr<int>(y);
    for (int x = 0; x < labels->cols; ++x) {
      int& target = remap[l[x]];
      if (target < 0) target = next++;
      l[x] = target;
    }
  }
  return next;
}

}  // namespace

void ComputeSuperpixelStats(const cv::Mat& lab, Superpixels* sp) {
  PX_CHECK(lab.type() == CV_8UC3 && sp->labels.type() == CV_32S && lab.size() == sp->labels.size());
  const int n = sp->count;
  sp->sizes.assign(n, 0);
  sp->bboxes.assign(n, cv::Rect());
  sp->mean_lab.assign(n, cv::Vec3f(0, 0, 0));
  sp->centroids.assign(n, cv::Point2f(0, 0));
  std::vector<cv::Vec4i> extent(n, cv::Vec4i(lab.cols, lab.rows, -1, -1));  // x0, y0, x1, y1
  for (int y = 0; y < lab.rows; ++y) {
    const int* l = sp->labels.ptr<int>(y);
    const cv::Vec3b* c = lab.ptr<cv::Vec3b>(y);
    for (int x = 0; x < lab.cols; ++x) {
      const int s = l[x];
      ++sp->sizes[s];
      sp->mean_lab[s] += cv::Vec3f(c[x][0], c[x][1], c[x][2]);
      sp->centroids[s] += cv::Point2f(static_cast<float>(x), static_cast<float>(y));
      cv::Vec4i& e = extent[s];
      e[0] = std::min(e[0], x);
      e[1] = std::min(e[1], y);
      e[2] = std::max(e[2], x);
      e[3] = std::max(e[3], y);
    }
  }
  for (int s = 0; s < n; ++s) {
    if (sp->sizes[s] > 0) {
      sp->mean_lab[s] /= static_cast<float>(sp->sizes[s]);
      sp->centroids[s] /= static_cast<float>(sp->sizes[s]);
    }
    const cv::Vec4i& e = extent[s];
    sp->bboxes[s] = sp->sizes[s] > 0 ? cv::Rect(e[0], e[1], e[2] - e[0] + 1, e[3] - e[1] + 1) : cv::Rect();
  }
  sp->adjacent = AdjacentLabels(sp->labels, n);
}

std::vector<std::vector<int>> AdjacentLabels(const cv::Mat& labels, int count) {
  std::vector<std::vector<int>> adjacent(count);
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const int* below = y + 1 < labels.rows ? labels.ptr<int>(y + 1) : nullptr;
    for (int x = 0; x < labels.cols; ++x) {
      const int s = l[x];
      const int right = x + 1 < labels.cols ? l[x + 1] : s;
      const int down = below != nullptr ? below[x] : s;
      for (int other : {right, down}) {
        if (other == s) continue;
        // Most pixels repeat the last pair: check it before searching.
        if (adjacent[s].empty() || adjacent[s].back() != other) adjacent[s].push_back(other);
        if (adjacent[other].empty() || adjacent[other].back() != s) adjacent[other].push_back(s);
      }
    }
  }
  for (std::vector<int>& list : adjacent) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  return adjacent;
}

std::vector<std::vector<int>> SegmentPixels(const Superpixels& sp) {
  std::vector<std::vector<int>> pixels(sp.count);
  for (int s = 0; s < sp.count; ++s) pixels[s].reserve(sp.sizes[s]);
  for (int y = 0; y < sp.labels.rows; ++y) {
    const int* l = sp.labels.ptr<int>(y);
    for (int x = 0; x < sp.labels.cols; ++x) pixels[l[x]].push_back(y * sp.labels.cols + x);
  }
  return pixels;
}

Superpixels Oversegment(const cv::Mat& bgr, int region_size_px, float ruler, int iterations) {
  PX_CHECK(bgr.type() == CV_8UC3);
  cv::Mat blurred, lab;
  cv::GaussianBlur(bgr, blurred, cv::Size(3, 3), 0);
  cv::cvtColor(blurred, lab, cv::COLOR_BGR2Lab);
  cv::Ptr<cv::ximgproc::SuperpixelSLIC> slic =
      cv::ximgproc::createSuperpixelSLIC(lab, cv::ximgproc::SLIC, region_size_px, ruler);
  slic->iterate(iterations);
  slic->enforceLabelConnectivity(25);
  Superpixels sp;
  slic->getLabels(sp.labels);
  sp.count = CompactLabels(&sp.labels);
  ComputeSuperpixelStats(lab, &sp);
  return sp;
}

cv::Mat UpsampleLabels(const Superpixels& superpixels, const cv::Mat& bgr, double factor) {
  PX_CHECK(bgr.type() == CV_8UC3 && factor > 0 && factor <= 1);
  const cv::Mat& small = superpixels.labels;
  cv::Mat blurred, lab;
  cv::GaussianBlur(bgr, blurred, cv::Size(3, 3), 0);
  cv::cvtColor(blurred, lab, cv::COLOR_BGR2Lab);
  cv::Mat labels(bgr.size(), CV_32S);
  cv::parallel_for_(cv::Range(0, bgr.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      // Working-scale position of this pixel centre: x' + 0.5 = (x + 0.5) * factor.
      const double ys = std::clamp((y + 0.5) * factor - 0.5, 0.0, small.rows - 1.0);
      const int y0 = static_cast<int>(ys), y1 = std::min(y0 + 1, small.rows - 1);
      const cv::Vec3b* c = lab.ptr<cv::Vec3b>(y);
      int* out = labels.ptr<int>(y);
      for (int x = 0; x < bgr.cols; ++x) {
        const double xs = std::clamp((x + 0.5) * factor - 0.5, 0.0, small.cols - 1.0);
        const int x0 = static_cast<int>(xs), x1 = std::min(x0 + 1, small.cols - 1);
        const int candidates[4] = {
            small.at<int>(y0, x0), small.at<int>(y0, x1), small.at<int>(y1, x0), small.at<int>(y1, x1)};
        // The nearest working pixel's label unless another candidate's colour fits better.
        int best = small.at<int>(std::lround(ys), std::lround(xs));
        float best_distance = 1e30f;
        for (int candidate : candidates) {
          const cv::Vec3f d = superpixels.mean_lab[candidate] - cv::Vec3f(c[x]);
          const float distance = d.dot(d);
          if (distance < best_distance - 1e-3f) {
            best_distance = distance;
            best = candidate;
          }
        }
        out[x] = best;
      }
    }
  });
  return labels;
}

}  // namespace px::depth
