// The paper's two-layer representation at depth discontinuities (section 5): where two touching
// segments' planes disagree by more than a depth-edge threshold, a band of pixels on both sides
// of the edge is shared between them: the front (foreground) segment in layer 0 with an alpha
// that falls from 1 inside it to 0 inside the background (the pixel's colour between the two
// carried colours where they differ, else a linear ramp), the background segment extended
// under it in layer 1 with the complement, each with its own colour carried in from its pure
// pixels. The renderer then separates foreground from background without halos; elsewhere a
// pixel belongs to its own segment alone.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/layered_depth.h"
#include "pipeline/core/view.h"
#include "pipeline/depth/segment_planes.h"

namespace px::depth {

struct TwoLayerOptions {
  // Touching segments whose planes differ by more than this in inverse depth (1/m) at their
  // shared border form a depth edge. > 0.
  double edge_inverse_depth_m = 0;
  // Half-width of the soft band, pixels at view resolution: pixels closer than this to a depth
  // edge are shared by both segments. [1, 16].
  int band_radius_px = 2;
  // Planes must keep inverse depth at least this (1/m) over the pixels they cover; a plane that
  // does not is replaced by a fronto-parallel one at its value at the segment's centre. > 0.
  double min_inverse_depth_m = 0;
};

struct SegmentImage {
  cv::Mat labels;                    // CV_32S at view resolution, 0 .. planes.size() - 1
  std::vector<InversePlane> planes;  // per segment, in the view's pixel coordinates
  std::vector<float> confidence;     // per segment, [0, 1]
};

// The layered view of `segments` over `bgr` (CV_8UC3, the camera's size). `pixel_confidence`
// (CV_32F, same size) becomes the view's confidence; depth_m is the depth of the pixel's
// dominant layer (the larger weight). The result passes ValidateLayeredDepthView.
LayeredDepthView BuildTwoLayerView(ViewId id,
                                   const CameraModel& camera,
                                   const cv::Mat& bgr,
                                   const SegmentImage& segments,
                                   const cv::Mat& pixel_confidence,
                                   const TwoLayerOptions& options);

// Pixels shared by two layers (weight of layer 1 > 0).
int CountBoundaryPixels(const LayeredDepthView& view);

}  // namespace px::depth
