// The multi-view matching cost of a slanted plane over one segment: every pixel of the segment
// (and a thin ring around it, where its texture contrast is) is carried into each neighbour view
// through the plane, exactly (no fronto-parallel window), and compared with ZNCC over the whole
// segment; the best half of the neighbours count (occlusions), as in the plane sweep. This is the
// score of segment-level PatchMatch (refine_segment_planes.h): on a steeply slanted, weakly
// textured surface the sweep's 5x5 fronto-parallel windows are biased and noisy, while one
// correlation over the segment along the true slant is neither.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/depth/plane_homography.h"
#include "pipeline/depth/segment_planes.h"
#include "pipeline/depth/superpixels.h"
#include "pipeline/depth/working_view.h"

namespace px::depth {

// A neighbour's grey image (CV_32F) and how reference pixels map into it.
struct GrayNeighbour {
  const cv::Mat* gray = nullptr;
  InverseDepthMapping mapping;
};

// `views`' grey images and how `ref`'s pixels map into them.
std::vector<GrayNeighbour> GrayNeighbours(const WorkingView& ref, const std::vector<const WorkingView*>& views);

// Variance of `gray` (CV_32F) over `pixels` (0 for none): whether they have texture to match.
double GreyVariance(const cv::Mat& gray, const std::vector<cv::Point>& pixels);

// Mean of the best half of the neighbours' 1 - ZNCC (in [0, 2]) between the reference's grey
// values at `pixels` and each neighbour's where `plane` carries them; a neighbour that sees
// fewer than half of them (or fewer than 4) does not count; kNoDataCost when none does.
// At most 16 neighbours.
double BestHalfZnccCost(const cv::Mat& ref_gray,
                        const std::vector<GrayNeighbour>& neighbours,
                        const std::vector<cv::Point>& pixels,
                        const InversePlane& plane);

class SegmentMatchCost {
 public:
  // `ref` and `neighbours` at the working scale (the segments' pixel grid; at most 16
  // neighbours, their grey images borrowed). A segment's ring is the pixels within `ring_px` of
  // it whose own inverse depth (`pixel_inverse_depth`, CV_32F) lies within `ring_tolerance` (1/m)
  // of its plane in `planes`: the same surface continued, where its texture's contrast often is,
  // and not an occluder's edge, which would drag the segment to the occluder's depth. Segments
  // whose pixels vary less than `min_texture_stddev` (grey, [0, 1]) have no texture.
  SegmentMatchCost(const WorkingView& ref,
                   const std::vector<const WorkingView*>& neighbours,
                   const Superpixels& segments,
                   const cv::Mat& pixel_inverse_depth,
                   const std::vector<SegmentPlane>& planes,
                   int ring_px,
                   double ring_tolerance,
                   double min_texture_stddev);

  // Mean of the best half of the neighbours' 1 - ZNCC over the segment, in [0, 2]; kNeutralCost
  // for a segment without texture, kNoDataCost when no neighbour sees half of it. Thread-safe.
  double operator()(int segment, const InversePlane& plane) const;

 private:
  std::vector<GrayNeighbour> neighbours_;
  std::vector<std::vector<cv::Point>> pixels_;  // per segment, with its ring
  std::vector<char> textured_;                  // per segment
  cv::Mat ref_gray_;
};

}  // namespace px::depth
