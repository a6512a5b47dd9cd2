#include "pipeline/depth/edge_labels.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/check.h"
#include "pipeline/depth/plane_homography.h"

namespace px::depth {
namespace {

constexpr int kMaxCandidates = 6;
constexpr size_t kMaxNeighbours = 16;

struct Projector {
  const cv::Mat* bgr = nullptr;
  InverseDepthMapping mapping;
  // Per pixel of the view, the largest inverse depth (in its camera) of the reference's surfaces
  // that land there: what the view sees in front; empty without visibility.
  cv::Mat nearest;
};

// A pixel near a depth edge: its candidates (labels, its own first) and their data costs.
struct EdgePixel {
  int x = 0, y = 0;
  int count = 0;
  std::array<int, kMaxCandidates> labels{};
  std::array<float, kMaxCandidates> cost{};
};

std::vector<Projector> MakeProjectors(const View& reference, const std::vector<const View*>& neighbours) {
  std::vector<Projector> projectors;
  for (const View* view : neighbours) {
    projectors.push_back(
        {&view->image, MappingInto(reference.camera, reference.cam_from_world, view->camera, view->cam_from_world)});
  }
  return projectors;
}

// Each projector's `nearest`: every reference pixel, carried by its segment's plane, marks the
// view pixel it lands nearest to.
void SplatReferenceSurfaces(const SegmentImage& image, std::vector<Projector>* projectors) {
  for (Projector& p : *projectors) {
    p.nearest = cv::Mat::zeros(p.bgr->size(), CV_32F);
    for (int y = 0; y < image.labels.rows; ++y) {
      const int* row = image.labels.ptr<int>(y);
      for (int x = 0; x < image.labels.cols; ++x) {
        const double u = image.planes[row[x]].At(x, y);
        double sx, sy, u_view;
        if (!(u > 0) || !p.mapping.Map(x, y, u, &sx, &sy, &u_view)) continue;
        sx += 0.5;  // truncation then rounds
        sy += 0.5;
        if (!(sx >= 0 && sy >= 0 && sx < p.nearest.cols && sy < p.nearest.rows)) continue;
        float& nearest = p.nearest.at<float>(static_cast<int>(sy), static_cast<int>(sx));
        nearest = std::max(nearest, static_cast<float>(u_view));
      }
    }
  }
}

// Pixels where the label changes to one whose plane lies more than the edge threshold away.
cv::Mat DepthEdgeSeeds(const SegmentImage& image, double edge_inverse_depth) {
  const cv::Mat& labels = image.labels;
  cv::Mat seeds = cv::Mat::zeros(labels.size(), CV_8U);
  for (int y = 0; y < labels.rows; ++y) {
    const int* row = labels.ptr<int>(y);
    const int* below = y + 1 < labels.rows ? labels.ptr<int>(y + 1) : nullptr;
    uint8_t* seed = seeds.ptr<uint8_t>(y);
    for (int x = 0; x < labels.cols; ++x) {
      const int own = row[x];
      const int others[2] = {x + 1 < labels.cols ? row[x + 1] : own, below ? below[x] : own};
      for (int other : others) {
        if (other == own) continue;
        if (std::abs(image.planes[other].At(x, y) - image.planes[own].At(x, y)) > edge_inverse_depth) seed[x] = 1;
      }
    }
  }
  return seeds;
}

// Pixels within `radius` of a depth edge, with the distinct labels around them as candidates.
std::vector<EdgePixel> FindEdgePixels(const SegmentImage& image, const EdgeLabelOptions& options) {
  const cv::Mat& labels = image.labels;
  const int r = options.radius_px;
  cv::Mat near_edge;
  cv::dilate(DepthEdgeSeeds(image, options.edge_inverse_depth_m),
             near_edge,
             cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * r + 1, 2 * r + 1)));
  std::vector<EdgePixel> edge;
  for (int y = 0; y < labels.rows; ++y) {
    const uint8_t* near_row = near_edge.ptr<uint8_t>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (!near_row[x]) continue;
      EdgePixel p;
      p.x = x;
      p.y = y;
      p.labels[p.count++] = labels.at<int>(y, x);
      for (int dy = -r; dy <= r && p.count < kMaxCandidates; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= labels.rows) continue;
        const int* row = labels.ptr<int>(yy);
        int previous = -1;  // runs of one label along the row are looked up once
        for (int dx = -r; dx <= r && p.count < kMaxCandidates; ++dx) {
          const int xx = x + dx;
          if (xx < 0 || xx >= labels.cols || row[xx] == previous) continue;
          previous = row[xx];
          if (std::find(p.labels.begin(), p.labels.begin() + p.count, previous) == p.labels.begin() + p.count) {
            p.labels[p.count++] = previous;
          }
        }
      }
      if (p.count > 1) edge.push_back(p);
    }
  }
  return edge;
}

// The truncated colour difference between the reference pixel and where the plane (inverse
// depth u at the pixel) carries it: the mean over the views that see that point where at least
// `min_visible` do (`occlusion_margin` > 0), else over the better half of all the views; -1 where
// no view holds it.
float PlaneColourCost(const cv::Vec3b& colour,
                      int x,
                      int y,
                      double u,
                      const std::vector<Projector>& projectors,
                      float truncation,
                      double occlusion_margin,
                      int min_visible) {
  std::array<float, kMaxNeighbours> costs;
  std::array<char, kMaxNeighbours> hidden{};
  int n = 0, num_hidden = 0;
  for (const Projector& p : projectors) {
    double sx, sy, u_view;
    if (!p.mapping.Map(x, y, u, &sx, &sy, &u_view)) continue;
    const cv::Mat& src = *p.bgr;
    if (!(sx >= 0 && sy >= 0 && sx <= src.cols - 2 && sy <= src.rows - 2)) continue;
    if (occlusion_margin > 0) {
      const float in_front = p.nearest.at<float>(static_cast<int>(std::lround(sy)), static_cast<int>(std::lround(sx)));
      hidden[n] = in_front > u_view + occlusion_margin;
      num_hidden += hidden[n];
    }
    const int x0 = static_cast<int>(sx), y0 = static_cast<int>(sy);
    const float fx = static_cast<float>(sx - x0), fy = static_cast<float>(sy - y0);
    const cv::Vec3b* r0 = src.ptr<cv::Vec3b>(y0) + x0;
    const cv::Vec3b* r1 = src.ptr<cv::Vec3b>(y0 + 1) + x0;
    float diff = 0;
    for (int c = 0; c < 3; ++c) {
      const float v = (1 - fy) * ((1 - fx) * r0[0][c] + fx * r0[1][c]) + fy * ((1 - fx) * r1[0][c] + fx * r1[1][c]);
      diff += std::abs(v - colour[c]);
    }
    costs[n++] = std::min(diff / 3.0f, truncation);
  }
  if (n == 0) return -1;
  const int visible = n - num_hidden;
  if (occlusion_margin > 0 && visible >= min_visible) {
    float sum = 0;
    for (int k = 0; k < n; ++k) sum += hidden[k] ? 0.0f : costs[k];
    return sum / visible;
  }
  std::sort(costs.begin(), costs.begin() + n);
  const int keep = (n + 1) / 2;
  float sum = 0;
  for (int k = 0; k < keep; ++k) sum += costs[k];
  return sum / keep;
}

// Drops the segments that cover no pixel any more (a sliver of halo that went wholly to its
// neighbours), renumbering the rest in order, so that every segment of the layered view has
// pixels. Returns how many were dropped.
int DropEmptySegments(SegmentImage* image) {
  const int count = static_cast<int>(image->planes.size());
  std::vector<int> pixels(count, 0);
  for (int y = 0; y < image->labels.rows; ++y) {
    const int* row = image->labels.ptr<int>(y);
    for (int x = 0; x < image->labels.cols; ++x) ++pixels[row[x]];
  }
  std::vector<int> renumbered(count, -1);
  int kept = 0;
  for (int s = 0; s < count; ++s) {
    if (pixels[s] == 0) continue;
    renumbered[s] = kept;
    image->planes[kept] = image->planes[s];
    image->confidence[kept] = image->confidence[s];
    ++kept;
  }
  if (kept == count) return 0;
  image->planes.resize(kept);
  image->confidence.resize(kept);
  for (int y = 0; y < image->labels.rows; ++y) {
    int* row = image->labels.ptr<int>(y);
    for (int x = 0; x < image->labels.cols; ++x) row[x] = renumbered[row[x]];
  }
  return count - kept;
}

}  // namespace

EdgeLabelStats RefineDepthEdgeLabels(const View& reference,
                                     const std::vector<const View*>& neighbours,
                                     const EdgeLabelOptions& options,
                                     SegmentImage* image) {
  PX_CHECK(image != nullptr && image->labels.type() == CV_32SC1 && image->labels.size() == reference.image.size());
  PX_CHECK(reference.image.type() == CV_8UC3 && image->confidence.size() == image->planes.size());
  PX_CHECK(options.edge_inverse_depth_m > 0 && options.radius_px >= 1 && options.radius_px <= 8);
  PX_CHECK(options.truncation > 0 && options.smoothness >= 0 && options.iterations >= 1 && options.iterations <= 10);
  PX_CHECK(neighbours.size() <= kMaxNeighbours) << "at most 16 neighbours";
  PX_CHECK(options.min_visible_views >= 1 && options.min_visible_views <= 16);
  EdgeLabelStats stats;
  if (neighbours.empty()) return stats;
  std::vector<Projector> projectors = MakeProjectors(reference, neighbours);
  const double occlusion_margin = options.visibility ? options.edge_inverse_depth_m : 0.0;
  if (options.visibility) SplatReferenceSurfaces(*image, &projectors);
  std::vector<EdgePixel> edge = FindEdgePixels(*image, options);
  stats.reconsidered = static_cast<int>(edge.size());
  const float truncation = static_cast<float>(options.truncation);
  // Data costs once; pixels no view sees under some candidate keep their label.
  std::vector<char> decidable(edge.size(), 1);
  for (size_t i = 0; i < edge.size(); ++i) {
    EdgePixel& p = edge[i];
    const cv::Vec3b colour = reference.image.at<cv::Vec3b>(p.y, p.x);
    for (int k = 0; k < p.count; ++k) {
      p.cost[k] = PlaneColourCost(colour,
                                  p.x,
                                  p.y,
                                  image->planes[p.labels[k]].At(p.x, p.y),
                                  projectors,
                                  truncation,
                                  occlusion_margin,
                                  options.min_visible_views);
      if (p.cost[k] < 0) decidable[i] = 0;
    }
  }
  const cv::Mat original = image->labels.clone();
  cv::Mat& labels = image->labels;
  const float smoothness = static_cast<float>(options.smoothness);
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    int changes = 0;
    for (size_t i = 0; i < edge.size(); ++i) {
      if (!decidable[i]) continue;
      const EdgePixel& p = edge[i];
      int best = labels.at<int>(p.y, p.x);
      float best_cost = std::numeric_limits<float>::max();
      for (int k = 0; k < p.count; ++k) {
        int differing = 0;
        for (int dy = -1; dy <= 1; ++dy) {
          const int yy = p.y + dy;
          if (yy < 0 || yy >= labels.rows) continue;
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = p.x + dx;
            if ((dx == 0 && dy == 0) || xx < 0 || xx >= labels.cols) continue;
            differing += labels.at<int>(yy, xx) != p.labels[k];
          }
        }
        const float cost = p.cost[k] + smoothness * differing;
        if (cost < best_cost) {
          best_cost = cost;
          best = p.labels[k];
        }
      }
      if (best != labels.at<int>(p.y, p.x)) {
        labels.at<int>(p.y, p.x) = best;
        ++changes;
      }
    }
    if (changes == 0) break;
  }
  stats.changed = cv::countNonZero(labels != original);
  stats.dropped_segments = DropEmptySegments(image);
  return stats;
}

}  // namespace px::depth
