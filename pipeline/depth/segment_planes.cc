#include "pipeline/depth/segment_planes.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "pipeline/core/check.h"

namespace px::depth {
namespace {

using Sample = PlaneSample;

// Weighted least squares u = a (x - mx) + b (y - my) + c' over the samples flagged in `use`,
// with a small ridge on the slopes so that a segment thin in one direction gets a level plane
// along it instead of a wild slope.
bool FitWeighted(const std::vector<Sample>& samples, const std::vector<char>& use, InversePlane* plane) {
  double sw = 0, sx = 0, sy = 0;
  for (size_t i = 0; i < samples.size(); ++i) {
    if (!use[i]) continue;
    const Sample& s = samples[i];
    sw += s.w;
    sx += s.w * s.x;
    sy += s.w * s.y;
  }
  if (sw <= 0) return false;
  const double mx = sx / sw, my = sy / sw;
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d atb = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < samples.size(); ++i) {
    if (!use[i]) continue;
    const Sample& s = samples[i];
    const Eigen::Vector3d row(s.x - mx, s.y - my, 1.0);
    ata += s.w * row * row.transpose();
    atb += s.w * s.u * row;
  }
  constexpr double kRidgePx2 = 1.0;  // as if one pixel of spread in each direction held the slope at 0
  ata(0, 0) += kRidgePx2 * sw;
  ata(1, 1) += kRidgePx2 * sw;
  const Eigen::Vector3d solution = ata.ldlt().solve(atb);
  if (!solution.allFinite()) return false;
  plane->a = solution(0);
  plane->b = solution(1);
  plane->c = solution(2) - solution(0) * mx - solution(1) * my;
  return true;
}

// Plane through three samples; false when they are (nearly) collinear.
bool PlaneThrough(const Sample& p, const Sample& q, const Sample& r, InversePlane* plane) {
  const double x1 = q.x - p.x, y1 = q.y - p.y, x2 = r.x - p.x, y2 = r.y - p.y;
  const double det = x1 * y2 - x2 * y1;
  if (std::abs(det) < 1.0) return false;  // twice the triangle area below 0.5 px^2
  const double u1 = q.u - p.u, u2 = r.u - p.u;
  plane->a = (u1 * y2 - u2 * y1) / det;
  plane->b = (x1 * u2 - x2 * u1) / det;
  plane->c = p.u - plane->a * p.x - plane->b * p.y;
  return true;
}

double WeightedMedianU(std::vector<Sample> samples) {
  std::sort(samples.begin(), samples.end(), [](const Sample& l, const Sample& r) { return l.u < r.u; });
  double total = 0;
  for (const Sample& s : samples) total += s.w;
  double acc = 0;
  for (const Sample& s : samples) {
    acc += s.w;
    if (acc >= 0.5 * total) return s.u;
  }
  return samples.back().u;
}

// xorshift64*: a small deterministic generator per segment.
uint64_t NextRandom(uint64_t* state) {
  *state ^= *state >> 12;
  *state ^= *state << 25;
  *state ^= *state >> 27;
  return *state * 0x2545F4914F6CDD1DULL;
}

SegmentPlane FitOne(const std::vector<Sample>& samples,
                    int segment_size,
                    const PlaneFitOptions& options,
                    uint64_t seed) {
  SegmentPlane result;
  const int n = static_cast<int>(samples.size());
  if (n < options.min_pixels) return result;
  const double tolerance = options.inlier_tolerance;
  uint64_t state = seed * 0x9E3779B97F4A7C15ULL + 1;
  InversePlane best;
  double best_score = -1;
  std::vector<char> inliers(n, 0), best_inliers(n, 0);
  const auto score_of = [&](const InversePlane& plane, std::vector<char>* flags) {
    double score = 0;
    for (int i = 0; i < n; ++i) {
      const Sample& s = samples[i];
      const bool in = std::abs(s.u - plane.At(s.x, s.y)) <= tolerance;
      (*flags)[i] = in ? 1 : 0;
      score += in ? s.w : 0.0;
    }
    return score;
  };
  // The fronto-parallel plane at the weighted median is always a candidate.
  InversePlane fronto;
  fronto.c = WeightedMedianU(samples);
  best = fronto;
  best_score = score_of(fronto, &best_inliers);
  for (int it = 0; it < options.ransac_iterations; ++it) {
    const Sample& p = samples[NextRandom(&state) % n];
    const Sample& q = samples[NextRandom(&state) % n];
    const Sample& r = samples[NextRandom(&state) % n];
    InversePlane candidate;
    if (!PlaneThrough(p, q, r, &candidate)) continue;
    const double score = score_of(candidate, &inliers);
    if (score > best_score) {
      best_score = score;
      best = candidate;
      best_inliers.swap(inliers);
    }
  }
  // Refit on the inliers, then once more on the refit's own inliers.
  for (int round = 0; round < 2; ++round) {
    InversePlane refit;
    if (!FitWeighted(samples, best_inliers, &refit)) break;
    std::vector<char> refit_inliers(n, 0);
    const double score = score_of(refit, &refit_inliers);
    if (score + 1e-9 < best_score * 0.98) break;  // the refit lost support: keep the sample plane
    best = refit;
    best_score = score;
    best_inliers.swap(refit_inliers);
  }
  int count = 0;
  double weight_sum = 0;
  for (int i = 0; i < n; ++i) {
    count += best_inliers[i];
    weight_sum += best_inliers[i] ? samples[i].w : 0.0;
  }
  result.plane = best;
  result.support = static_cast<float>(count) / static_cast<float>(segment_size);
  result.confidence = count > 0 ? static_cast<float>(result.support * weight_sum / count) : 0.0f;
  result.confidence = std::clamp(result.confidence, 0.0f, 1.0f);
  if (result.support < options.min_support) {
    result.source = PlaneSource::kFronto;  // weak: a candidate for propagation
    result.plane = fronto;
  } else {
    result.source = best.a == 0 && best.b == 0 ? PlaneSource::kFronto : PlaneSource::kFitted;
  }
  return result;
}

}  // namespace

void ConfidentSamples(const std::vector<int>& pixels,
                      const cv::Mat& inverse_depth,
                      const cv::Mat& weight,
                      float min_weight,
                      std::vector<PlaneSample>* samples) {
  samples->clear();
  const int cols = weight.cols;
  for (int index : pixels) {
    const int x = index % cols, y = index / cols;
    const float w = weight.at<float>(y, x);
    if (w < min_weight) continue;
    samples->push_back({static_cast<float>(x), static_cast<float>(y), inverse_depth.at<float>(y, x), w});
  }
}

std::vector<SegmentPlane> FitSegmentPlanes(const Superpixels& segments,
                                           const cv::Mat& inverse_depth,
                                           const cv::Mat& weight,
                                           const PlaneFitOptions& options) {
  PX_CHECK(inverse_depth.type() == CV_32F && weight.type() == CV_32F &&
           inverse_depth.size() == segments.labels.size() && weight.size() == segments.labels.size());
  PX_CHECK(options.inlier_tolerance > 0);
  const std::vector<std::vector<int>> pixels = SegmentPixels(segments);
  std::vector<SegmentPlane> planes(segments.count);
  cv::parallel_for_(cv::Range(0, segments.count), [&](const cv::Range& range) {
    std::vector<Sample> samples;
    for (int s = range.start; s < range.end; ++s) {
      ConfidentSamples(pixels[s], inverse_depth, weight, options.min_weight, &samples);
      planes[s] = FitOne(samples, segments.sizes[s], options, options.seed + static_cast<uint64_t>(s));
    }
  });
  return planes;
}

namespace {

// A plane an unfitted segment may take: its matching cost over the segment, and the adjacent
// segment it comes from (-1: the segment's own weak fronto-parallel plane).
struct PlaneCandidate {
  double cost = 0;
  InversePlane plane;
  int from = -1;
};

// Colour distances (Lab) closer than this count as equally close.
constexpr float kSameColourLab = 4.0f;

// The farthest candidate: smallest inverse depth at the segment's centre.
InversePlane FarthestCandidate(const std::vector<PlaneCandidate>& candidates, const cv::Point2f& centre) {
  const PlaneCandidate* chosen = &candidates.front();
  for (const PlaneCandidate& c : candidates) {
    if (c.plane.At(centre.x, centre.y) < chosen->plane.At(centre.x, centre.y)) chosen = &c;
  }
  return chosen->plane;
}

// Among the candidates within `margin` of the lowest cost, the neighbour closest in colour, and
// of those equally close, the farthest. Where the cost cannot tell the planes apart (no texture;
// an edge along the baselines, which matches at every depth), the surface the segment continues
// is the one that looks like it: a lit strip of a desk's front edge goes with the desk top, not
// with the dark recess below it. Where colour does not tell either, the background continues
// behind an occluder. The segment's own weak plane is taken only when no neighbour ties.
InversePlane TiedCandidate(const std::vector<PlaneCandidate>& candidates,
                           const Superpixels& segments,
                           int s,
                           double margin) {
  double best_cost = 1e300;
  for (const PlaneCandidate& c : candidates) best_cost = std::min(best_cost, c.cost);
  std::vector<const PlaneCandidate*> tied;
  std::vector<float> distance;
  float closest = std::numeric_limits<float>::infinity();
  for (const PlaneCandidate& c : candidates) {
    if (c.cost > best_cost + margin) continue;
    tied.push_back(&c);
    distance.push_back(c.from < 0 ? std::numeric_limits<float>::infinity()
                                  : static_cast<float>(cv::norm(segments.mean_lab[c.from] - segments.mean_lab[s])));
    closest = std::min(closest, distance.back());
  }
  const cv::Point2f centre = segments.centroids[s];
  const PlaneCandidate* chosen = nullptr;
  for (size_t i = 0; i < tied.size(); ++i) {
    if (std::isfinite(closest) && !(distance[i] <= closest + kSameColourLab)) continue;
    if (chosen == nullptr || tied[i]->plane.At(centre.x, centre.y) < chosen->plane.At(centre.x, centre.y)) {
      chosen = tied[i];
    }
  }
  return chosen->plane;
}

}  // namespace

void AssignUnfittedSegments(const Superpixels& segments,
                            const PlaneCost& cost,
                            const std::vector<float>& occluded_fraction,
                            const std::vector<float>& unseen_fraction,
                            double cost_margin,
                            std::vector<SegmentPlane>* planes) {
  const int n = segments.count;
  // Segments that need a plane, most-supported neighbours first: repeat sweeps until no segment
  // changes, each sweep taking segments with at least one settled neighbour.
  std::vector<char> settled(n, 0);
  for (int s = 0; s < n; ++s) settled[s] = (*planes)[s].source == PlaneSource::kFitted;
  bool any_settled = std::any_of(settled.begin(), settled.end(), [](char c) { return c != 0; });
  if (!any_settled) {
    // Nothing fitted anywhere: keep the weak fronto-parallel planes as they are.
    for (int s = 0; s < n; ++s) settled[s] = (*planes)[s].source != PlaneSource::kNone;
  }
  for (int sweep = 0; sweep < n; ++sweep) {
    std::vector<std::pair<float, int>> pending;  // (best neighbour support, segment)
    for (int s = 0; s < n; ++s) {
      if (settled[s]) continue;
      float best_support = -1;
      for (int t : segments.adjacent[s]) {
        if (settled[t]) best_support = std::max(best_support, (*planes)[t].support);
      }
      if (best_support >= 0) pending.emplace_back(best_support, s);
    }
    if (pending.empty()) break;
    std::sort(pending.begin(), pending.end(), [](const auto& l, const auto& r) { return l.first > r.first; });
    std::vector<std::pair<int, SegmentPlane>> updates;
    for (const auto& [support, s] : pending) {
      (void)support;
      const cv::Point2f centre = segments.centroids[s];
      std::vector<PlaneCandidate> candidates;
      if ((*planes)[s].source == PlaneSource::kFronto)
        candidates.push_back({cost(s, (*planes)[s].plane), (*planes)[s].plane, -1});
      for (int t : segments.adjacent[s]) {
        if (settled[t]) candidates.push_back({cost(s, (*planes)[t].plane), (*planes)[t].plane, t});
      }
      if (candidates.empty()) continue;
      SegmentPlane assigned = (*planes)[s];
      assigned.source = PlaneSource::kPropagated;
      assigned.confidence = std::min(assigned.confidence, 0.25f);
      if (!unseen_fraction.empty() && unseen_fraction[s] > 0.5f) {
        int closest = -1;
        float closest_distance = 0;
        for (int t : segments.adjacent[s]) {
          const float distance = static_cast<float>(cv::norm(segments.mean_lab[t] - segments.mean_lab[s]));
          if (settled[t] && (closest < 0 || distance < closest_distance)) {
            closest = t;
            closest_distance = distance;
          }
        }
        if (closest >= 0) {
          assigned.plane = (*planes)[closest].plane;
          updates.emplace_back(s, assigned);
          continue;
        }
      }
      const bool occluded = !occluded_fraction.empty() && occluded_fraction[s] > 0.5f;
      assigned.plane =
          occluded ? FarthestCandidate(candidates, centre) : TiedCandidate(candidates, segments, s, cost_margin);
      updates.emplace_back(s, assigned);
    }
    for (auto& [s, plane] : updates) {
      (*planes)[s] = plane;
      settled[s] = 1;
    }
  }
}

}  // namespace px::depth
