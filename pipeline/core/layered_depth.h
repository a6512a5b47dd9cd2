// The paper's per-view scene representation (section 5): each view is over-segmented into
// segments of planar depth; segments may overlap at depth boundaries, at most two covering any
// pixel, with per-pixel colour and weight so that a boundary pixel mixing foreground and
// background is split between them (soft alpha) instead of smearing one into the other.
//
// Producer: pipeline/depth (segment-based stereo). Consumers: pipeline/render (segments drawn as
// textured rectangles, paper 6.1) and pipeline/direct (subject depths, scene centroid). It lives
// in core so that neither consumer depends on the depth stage.
//
// Layer convention, per pixel p of a view:
//   layers[0] holds the front-most segment covering p, layers[1] the one behind it, if any;
//   weight0(p) + weight1(p) == 1 wherever some segment covers p (a pixel covered once has
//   weight1 == 0 and segment1 == kNoSegment); both 0 only where no segment has depth (invalid).
//   colour is the layer's own (un-mixed) colour estimate at p: the foreground colour in
//   layers[0] and the background colour in layers[1] at a boundary.
#pragma once

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/status.h"
#include "pipeline/core/view.h"

namespace px {

// One segment: a planar patch of the scene seen by one view.
struct DepthSegment {
  // Inverse depth over a 3D plane is affine in pixel coordinates: 1 / z = a * x + b * y + c,
  // with (x, y) view pixels (OpenCV centres) and z metres along the view's optical axis.
  // A fronto-parallel segment at depth z0 has a = b = 0, c = 1 / z0.
  double inv_depth_a = 0;
  double inv_depth_b = 0;
  double inv_depth_c = 0;
  cv::Rect bbox;           // the pixels it covers in either layer, within the view
  float confidence = 0;    // [0, 1]: how much the stereo stage trusts this segment's plane
  int32_t num_pixels = 0;  // pixels it covers with weight > 0, in either layer

  // Inverse depth (1/m) of the plane at pixel (x, y) of the view.
  double InverseDepthAt(double x, double y) const { return inv_depth_a * x + inv_depth_b * y + inv_depth_c; }
  // Depth in metres at pixel (x, y) of the view; 0 when the plane is at or behind infinity there.
  double DepthAt(double x, double y) const {
    const double inv = InverseDepthAt(x, y);
    return inv > 0 ? 1.0 / inv : 0.0;
  }
};

// One of a view's two segment images.
struct SegmentLayer {
  static constexpr int32_t kNoSegment = -1;
  cv::Mat colour;   // CV_8UC3, BGR: this layer's colour at each pixel
  cv::Mat weight;   // CV_32F in [0, 1]: this layer's share of the pixel
  cv::Mat segment;  // CV_32S: index into LayeredDepthView::segments; kNoSegment where no segment
                    // covers the pixel (a band pixel keeps both, even where its matte weighs one 0)
};

struct LayeredDepthView {
  ViewId id;
  CameraModel camera;  // the view's pinhole camera (no distortion); all images are its size
  std::vector<DepthSegment> segments;
  std::array<SegmentLayer, 2> layers;  // [0] front, [1] behind it at boundaries (see above)
  // Per-pixel summaries for a plain depth map: z in metres of the dominant layer's plane (layers[0]
  // where its weight is >= 0.5, else layers[1]; 0 where no segment covers the pixel; or the depth
  // stage's own depth near that plane: pixel_depth_tolerance_px; held to the depth stage's swept
  // range, which a tilted plane can leave), and the stereo confidence in [0, 1].
  cv::Mat depth_m;     // CV_32F
  cv::Mat confidence;  // CV_32F

  int NumSegments() const { return static_cast<int>(segments.size()); }
  // Depth of layer `layer` at pixel (x, y): its segment's plane, 0 where the layer is empty.
  double LayerDepthAt(int layer, int x, int y) const;
  // CV_32F: at every pixel, the plane of its dominant layer (as depth_m, but exactly where the
  // renderer draws it: not held to any range); 0 where no segment covers the pixel.
  cv::Mat DominantPlaneDepth() const;
  // The plain DepthMap view of this (depth_m and confidence shared, not copied).
  DepthMap ToDepthMap() const;
};

// Checks the invariants above (sizes and types, weights in [0, 1] summing to 1 where covered,
// segment indices in range, each used segment's bbox containing its pixels, planes giving
// positive depth over their bbox). Errors name the view, the layer and the first bad pixel.
Status ValidateLayeredDepthView(const LayeredDepthView& view);

}  // namespace px
