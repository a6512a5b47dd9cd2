#include "pipeline/depth/refine_segment_planes.h"

#include <cmath>

#include "pipeline/core/check.h"

namespace px::depth {
namespace {

// xorshift64*, mapped to [-1, 1).
double NextSigned(uint64_t* state) {
  *state ^= *state >> 12;
  *state ^= *state << 25;
  *state ^= *state >> 27;
  const uint64_t bits = (*state * 0x2545F4914F6CDD1DULL) >> 11;
  return static_cast<double>(bits) * (2.0 / 9007199254740992.0) - 1.0;
}

// `plane` with its slopes changed by (da, db) and its value at `centre` by du.
InversePlane Perturbed(const InversePlane& plane, const cv::Point2f& centre, double du, double da, double db) {
  InversePlane out = plane;
  out.a += da;
  out.b += db;
  out.c += du - da * centre.x - db * centre.y;
  return out;
}

}  // namespace

int RefineSegmentPlanes(const Superpixels& segments,
                        const PlaneCost& cost,
                        const PlaneRefinementOptions& options,
                        std::vector<SegmentPlane>* planes) {
  PX_CHECK(static_cast<int>(planes->size()) == segments.count);
  const int n = segments.count;
  std::vector<double> best_cost(n, 0);
  for (int s = 0; s < n; ++s) {
    if ((*planes)[s].source != PlaneSource::kNone) best_cost[s] = cost(s, (*planes)[s].plane);
  }
  std::vector<char> changed(n, 0);
  std::vector<double> initial_centre(n);
  for (int s = 0; s < n; ++s)
    initial_centre[s] = (*planes)[s].plane.At(segments.centroids[s].x, segments.centroids[s].y);
  uint64_t state = options.seed * 0x9E3779B97F4A7C15ULL + 7;
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    const bool forward = iteration % 2 == 0;
    for (int i = 0; i < n; ++i) {
      const int s = forward ? i : n - 1 - i;
      SegmentPlane& current = (*planes)[s];
      if (current.source == PlaneSource::kNone || (!options.active.empty() && !options.active[s])) continue;
      const cv::Point2f centre = segments.centroids[s];
      const auto consider = [&](const InversePlane& candidate) {
        if (options.max_change_inverse_m > 0 &&
            std::abs(candidate.At(centre.x, centre.y) - initial_centre[s]) > options.max_change_inverse_m) {
          return;
        }
        const double c = cost(s, candidate);
        if (c < best_cost[s]) {
          best_cost[s] = c;
          current.plane = candidate;
          changed[s] = 1;
        }
      };
      // Propagation: the planes of the adjacent segments.
      for (int t : segments.adjacent[s]) {
        if ((*planes)[t].source != PlaneSource::kNone) consider((*planes)[t].plane);
      }
      // Refinement: ever smaller random changes of depth and slant around the best so far.
      double offset = options.offset_inverse_m, slope = options.slope_inverse_m_per_px;
      for (int trial = 0; trial < options.random_trials; ++trial, offset *= 0.5, slope *= 0.5) {
        const double du = offset * NextSigned(&state), da = slope * NextSigned(&state), db = slope * NextSigned(&state);
        consider(Perturbed(current.plane, centre, du, da, db));
      }
    }
  }
  int count = 0;
  for (char c : changed) count += c;
  return count;
}

}  // namespace px::depth
