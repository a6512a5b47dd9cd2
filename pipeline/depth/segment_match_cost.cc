#include "pipeline/depth/segment_match_cost.h"

#include <algorithm>
#include <cmath>

#include "pipeline/core/check.h"
#include "pipeline/depth/zncc_cost.h"

namespace px::depth {
namespace {

// Pixels of each segment and of its ring: every pixel joins the segments found within ring_px
// of it (a square neighbourhood) whose plane lies within `tolerance` of the pixel's own inverse
// depth (the ring is the same surface continued, not an occluder's edge).
std::vector<std::vector<cv::Point>> SegmentPixelsWithRing(const Superpixels& segments,
                                                          int ring_px,
                                                          const cv::Mat& inverse_depth,
                                                          const std::vector<SegmentPlane>& planes,
                                                          double tolerance) {
  std::vector<std::vector<cv::Point>> pixels(segments.count);
  const cv::Mat& labels = segments.labels;
  std::vector<int> seen;
  for (int y = 0; y < labels.rows; ++y) {
    for (int x = 0; x < labels.cols; ++x) {
      seen.clear();
      for (int dy = -ring_px; dy <= ring_px; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= labels.rows) continue;
        const int* row = labels.ptr<int>(yy);
        for (int dx = -ring_px; dx <= ring_px; ++dx) {
          const int xx = x + dx;
          if (xx < 0 || xx >= labels.cols) continue;
          const int s = row[xx];
          if (std::find(seen.begin(), seen.end(), s) == seen.end()) seen.push_back(s);
        }
      }
      const int own = labels.at<int>(y, x);
      const double u = inverse_depth.at<float>(y, x);
      for (int s : seen) {
        if (s == own || std::abs(u - planes[s].plane.At(x, y)) <= tolerance) pixels[s].emplace_back(x, y);
      }
    }
  }
  return pixels;
}

}  // namespace

SegmentMatchCost::SegmentMatchCost(const WorkingView& ref,
                                   const std::vector<const WorkingView*>& neighbours,
                                   const Superpixels& segments,
                                   const cv::Mat& pixel_inverse_depth,
                                   const std::vector<SegmentPlane>& planes,
                                   int ring_px,
                                   double ring_tolerance,
                                   double min_texture_stddev)
    : pixels_(SegmentPixelsWithRing(segments, ring_px, pixel_inverse_depth, planes, ring_tolerance)),
      ref_gray_(ref.gray) {
  PX_CHECK(ref.gray.type() == CV_32FC1 && segments.labels.size() == ref.gray.size() &&
           pixel_inverse_depth.type() == CV_32FC1 && pixel_inverse_depth.size() == ref.gray.size());
  PX_CHECK(neighbours.size() <= 16) << "at most 16 neighbours";
  neighbours_ = GrayNeighbours(ref, neighbours);
  const double min_variance = min_texture_stddev * min_texture_stddev;
  textured_.resize(pixels_.size());
  for (size_t s = 0; s < pixels_.size(); ++s) textured_[s] = GreyVariance(ref_gray_, pixels_[s]) > min_variance ? 1 : 0;
}

std::vector<GrayNeighbour> GrayNeighbours(const WorkingView& ref, const std::vector<const WorkingView*>& views) {
  std::vector<GrayNeighbour> out;
  for (const WorkingView* view : views) {
    out.push_back({&view->gray, MappingInto(ref.camera, ref.cam_from_world, view->camera, view->cam_from_world)});
  }
  return out;
}

double GreyVariance(const cv::Mat& gray, const std::vector<cv::Point>& pixels) {
  double sum = 0, sum_sq = 0;
  for (const cv::Point& p : pixels) {
    const double g = gray.at<float>(p);
    sum += g;
    sum_sq += g * g;
  }
  const double count = std::max<double>(pixels.size(), 1);
  const double mean = sum / count;
  return sum_sq / count - mean * mean;
}

double BestHalfZnccCost(const cv::Mat& ref_gray,
                        const std::vector<GrayNeighbour>& neighbours,
                        const std::vector<cv::Point>& pixels,
                        const InversePlane& plane) {
  PX_CHECK(neighbours.size() <= 16) << "at most 16 neighbours";
  const int count = static_cast<int>(pixels.size());
  float costs[16];
  int num_costs = 0;
  for (const GrayNeighbour& n : neighbours) {
    const cv::Mat& src = *n.gray;
    const int max_x = src.cols - 2, max_y = src.rows - 2;
    double sw = 0, sww = 0, sg = 0, sgg = 0, sgw = 0;
    int valid = 0;
    for (const cv::Point& p : pixels) {
      double sx, sy;
      if (!n.mapping.Map(p.x, p.y, plane.At(p.x, p.y), &sx, &sy)) continue;
      if (!(sx >= 0 && sy >= 0 && sx <= max_x && sy <= max_y)) continue;
      const int x0 = static_cast<int>(sx), y0 = static_cast<int>(sy);
      const float fx = static_cast<float>(sx - x0), fy = static_cast<float>(sy - y0);
      const float* r0 = src.ptr<float>(y0) + x0;
      const float* r1 = src.ptr<float>(y0 + 1) + x0;
      const double w = (1 - fy) * ((1 - fx) * r0[0] + fx * r0[1]) + fy * ((1 - fx) * r1[0] + fx * r1[1]);
      const double g = ref_gray.at<float>(p);
      sw += w;
      sww += w * w;
      sg += g;
      sgg += g * g;
      sgw += g * w;
      ++valid;
    }
    if (2 * valid < count || valid < 4) continue;
    const double var_g = valid * sgg - sg * sg, var_w = valid * sww - sw * sw;
    const double ncc = var_g > 0 && var_w > 0 ? (valid * sgw - sg * sw) / std::sqrt(var_g * var_w) : 0.0;
    costs[num_costs++] = static_cast<float>(std::clamp(1.0 - ncc, 0.0, 2.0));
  }
  if (num_costs == 0) return kNoDataCost;
  std::sort(costs, costs + num_costs);
  const int keep = (num_costs + 1) / 2;
  double sum = 0;
  for (int k = 0; k < keep; ++k) sum += costs[k];
  return sum / keep;
}

double SegmentMatchCost::operator()(int segment, const InversePlane& plane) const {
  if (!textured_[segment]) return kNeutralCost;
  return BestHalfZnccCost(ref_gray_, neighbours_, pixels_[segment], plane);
}

}  // namespace px::depth
