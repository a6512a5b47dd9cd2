// A plane per segment: inverse depth affine in pixel coordinates, u = a x + b y + c, fitted
// robustly (RANSAC on the confident pixels, then a weighted least-squares refit on the inliers)
// to the per-pixel stereo estimate. Segments without enough confident pixels (no texture,
// occlusions) take a plane from a neighbour: the one whose matching cost over the segment is
// lowest, or, where the segment is occluded in the other views, the farthest plausible one.
#pragma once

#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/depth/superpixels.h"

namespace px::depth {

struct InversePlane {
  double a = 0, b = 0, c = 0;  // u = a x + b y + c, in the pixel grid the plane was fitted in
  double At(double x, double y) const { return a * x + b * y + c; }
};

enum class PlaneSource : uint8_t {
  kFitted,      // from the segment's own confident pixels
  kFronto,      // too few or too clustered pixels for a slope: a fronto-parallel plane
  kPropagated,  // taken from an adjacent segment (see AssignUnfittedSegments)
  kNone,        // nothing to go on; filled with the scene's far end
};

struct SegmentPlane {
  InversePlane plane;
  PlaneSource source = PlaneSource::kNone;
  float support = 0;     // fraction of the segment's pixels that are confident inliers
  float confidence = 0;  // [0, 1]: support times the inliers' mean confidence
};

// A pixel a plane is fitted to: its position, inverse depth and weight.
struct PlaneSample {
  float x, y, u, w;
};

// The pixels of one segment (`pixels`: indices y * cols + x) whose `weight` (CV_32F) reaches
// `min_weight`, with their `inverse_depth` (CV_32F), in the pixels' order.
void ConfidentSamples(const std::vector<int>& pixels,
                      const cv::Mat& inverse_depth,
                      const cv::Mat& weight,
                      float min_weight,
                      std::vector<PlaneSample>* samples);

struct PlaneFitOptions {
  float min_weight = 0.2f;      // pixels with weight below this are not used
  double inlier_tolerance = 0;  // |u - plane| for an inlier, inverse-depth units (> 0)
  int ransac_iterations = 40;
  int min_pixels = 8;         // fewer usable pixels: the segment is not fitted
  double min_support = 0.15;  // fewer inliers than this fraction of the segment: not fitted
  uint64_t seed = 1;
};

// Fits every segment of `segments` to `inverse_depth` (CV_32F) using pixels whose `weight`
// (CV_32F in [0, 1]: confidence, 0 for pixels that failed the consistency check) reaches
// options.min_weight. Deterministic for a given seed.
std::vector<SegmentPlane> FitSegmentPlanes(const Superpixels& segments,
                                           const cv::Mat& inverse_depth,
                                           const cv::Mat& weight,
                                           const PlaneFitOptions& options);

// Mean matching cost of `plane` over segment s (lower is better), from the cost volume.
using PlaneCost = std::function<double(int segment, const InversePlane& plane)>;

// Gives every segment without a fitted plane (kNone, or kFronto with little support) one of its
// neighbours' planes, best-supported segments first so that planes spread inwards from
// textured regions: the candidate with the lowest cost, where costs within `cost_margin` of the
// best count as ties, broken towards the neighbour closest in colour (cost cannot tell planes
// apart on a flat region, nor on an edge that runs along the baselines, which matches at every
// depth; the surface a segment continues looks like it), and among neighbours alike in colour
// towards the farther plane (the background continues behind an occluder; the foreground rarely
// hides in flat regions). Segments whose pixels are mostly
// occluded (`occluded_fraction` > 0.5) take the farthest neighbour plane outright. Segments mostly
// outside every other view (`unseen_fraction` > 0.5: the strip along a border that the
// neighbours do not see at the far planes, CostVolume::sampled; what costs it has there, if any,
// are not trusted) have no occluder to go behind: they continue the
// adjacent surface closest to them in colour. Either vector may be empty (none).
void AssignUnfittedSegments(const Superpixels& segments,
                            const PlaneCost& cost,
                            const std::vector<float>& occluded_fraction,
                            const std::vector<float>& unseen_fraction,
                            double cost_margin,
                            std::vector<SegmentPlane>* planes);

}  // namespace px::depth
