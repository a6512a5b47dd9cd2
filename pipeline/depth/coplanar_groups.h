// Adjacent segments that lie on one plane take one plane fitted to all of them.
//
// A segment's own plane rests on its hundred or so confident pixels, so its depth wanders by a
// fraction of a pixel of disparity from segment to segment across a flat wall, a table or a
// photograph. Invisible at the lenses' own viewpoints, that noise becomes ghosting and seams
// once a dolly magnifies the surface (the close-up end of a dolly in). Segment-based stereo
// (Klaus et al. 2006, Bleyer and Gelautz 2005) cures it by fitting planes to groups of
// segments; here groups grow from the best-supported segments over their neighbours, and a
// neighbour joins only when the group's plane explains its confident pixels nearly as well as
// its own plane does, so curved surfaces and depth edges stop the growth.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/depth/segment_planes.h"
#include "pipeline/depth/superpixels.h"

namespace px::depth {

struct CoplanarGroupOptions {
  float min_weight = 0.2f;    // pixels with weight below this are not used (as PlaneFitOptions)
  double tolerance = 0;       // |u - plane| for an inlier, inverse-depth units (> 0)
  double min_support = 0.15;  // segments with less support neither seed nor join a group
  // A segment joins a group when the group's plane keeps at least this fraction of the weight
  // of its pixels that its own plane keeps within `tolerance`. (0, 1].
  double keep_fraction = 0.9;
};

struct CoplanarGroups {
  int groups = 0;             // groups of two segments or more, numbered 0 .. groups - 1
  int grouped_segments = 0;   // segments in them
  std::vector<int> group_of;  // per segment: its group, or -1
};

// Replaces the plane of every segment in a group of two or more with the group's weighted
// least-squares plane over its members' inlier pixels. Segments that are not fitted
// (PlaneSource other than kFitted and kFronto, or support under min_support) are left alone.
// `pixels` is SegmentPixels(segments); inverse_depth and weight as for FitSegmentPlanes.
// Deterministic.
CoplanarGroups MergeCoplanarSegments(const Superpixels& segments,
                                     const std::vector<std::vector<int>>& pixels,
                                     const cv::Mat& inverse_depth,
                                     const cv::Mat& weight,
                                     const CoplanarGroupOptions& options,
                                     std::vector<SegmentPlane>* planes);

}  // namespace px::depth
