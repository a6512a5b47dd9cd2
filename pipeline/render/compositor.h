// From segments to one blended image before hole filling: the preview's three rendering buffers
// with a soft z-buffer across them (ALGORITHM.md sections 4 and 5), and the offline soft z over
// all fragments of all contributing views (section 10). Both work in bands of rows in parallel.
#pragma once

#include <algorithm>
#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/render/layered_scene.h"
#include "pipeline/render/segment_raster.h"
#include "pipeline/render/view_mesh.h"

namespace px::render {

struct FrameComposite {
  long fragments = 0;    // fragments generated (before compositing)
  cv::Mat colour;        // CV_32FC3, 0..255, un-premultiplied where alpha > 0 (empty: coverage only)
  cv::Mat alpha;         // CV_32F, the blended alpha: covered where >= RenderOptions::covered_alpha
  cv::Mat depth;         // CV_32F, z in the novel camera, 0 where alpha == 0
  cv::Mat double_image;  // CV_8U, 255 on double images (BlendRules::measure_double_images; else empty)
  // The colour consensus's results where it changes a pixel, kept aside until the frame's regions
  // of such pixels are known (preview_compositor.cc); buffers reused from frame to frame.
  cv::Mat consensus_colour, consensus_alpha, consensus_depth, consensus_mark;
  // With BlendRules::one_view_regions, where the consensus changes a pixel: the pixel drawn from
  // its most heavily weighted view alone, and (CV_8UC2) the view the consensus outvoted there
  // (ViewSlots::kNone: none) and that view (else empty).
  cv::Mat solo_colour, solo_alpha, solo_depth, consensus_views;
};

// How the preview resolves a pixel whose views contradict each other (contradictions.h).
struct BlendRules {
  bool consistent = false;         // suppress the slots that more heavily weighted views contradict
  float dominance_exponent = 8;    // ConsistentBlendOptions::dominance_exponent
  float colour_agree_levels = 16;  // ConsistentBlendOptions::colour_agree_levels
  float colour_apart_levels = 32;  // ConsistentBlendOptions::colour_apart_levels
  bool one_view_regions = false;   // ConsistentBlendOptions::one_view_regions
  bool measure_double_images = false;
  int double_image_levels = 30;  // colours further apart than this (largest channel) are two images
};

// `slots` are the frame's viewing weights (width * height), `frame_views` its set-up segments.
// with_colour = false skips colour (Coverage()). `rules` (null: the plain soft z) say what to do
// where the scene's views contradict each other.
void CompositePreview(const LayeredScene& scene,
                      const std::vector<FrameView>& frame_views,
                      const std::vector<ViewSlots>& slots,
                      int width,
                      int height,
                      bool with_colour,
                      FrameComposite* out,
                      const BlendRules* rules = nullptr);

void CompositeOffline(const LayeredScene& scene,
                      const std::vector<FrameView>& frame_views,
                      const std::vector<ViewSlots>& slots,
                      int width,
                      int height,
                      FrameComposite* out);

// One row of a segment's projected rectangle: pixels [x_begin, x_end) of row y whose centres are
// inside it and that may hold its view, and the row's terms of the homogeneous source coordinates
// (hx0 + h[0] x, hy0 + h[3] x, hw0 + h[6] x) and of the inverse depth (iz0 + inv_depth[0] x).
struct SegmentRow {
  int y = 0, x_begin = 0, x_end = 0;
  float hx0 = 0, hy0 = 0, hw0 = 0, iz0 = 0;
};

// The source pixel (u, v) of setup `s`'s fragment at column fx of row `r`: false when the
// homography puts it behind the source camera or outside the segment's rectangle (rounding at the
// rectangle's edges). The far edges are excluded: the sampler reads the texels right of and below
// (u, v), which must lie within the one-texel border around the image, and a sample exactly on the
// far edge has all its weight on texels outside the segment anyway.
inline bool FragmentSource(
    const SegmentSetup& s, const SceneSegment& segment, const SegmentRow& r, float fx, float* u, float* v) {
  const float* h = s.homography.data();
  const float hw = h[6] * fx + r.hw0;
  if (!(hw > 0)) return false;
  const float inv_w = 1.0f / hw;
  *u = (h[0] * fx + r.hx0) * inv_w;
  *v = (h[3] * fx + r.hy0) * inv_w;
  return *u >= segment.rect[0] && *u < segment.rect[2] && *v >= segment.rect[1] && *v < segment.rect[3];
}

// Calls row(SegmentRow) for each row of setup `s` within [row_begin, row_end) that has pixels.
template <typename Row>
inline void ForEachSegmentRow(
    const FrameView& frame_view, const SegmentSetup& s, int width, int row_begin, int row_end, Row&& row) {
  const float* h = s.homography.data();
  const int y_begin = std::max(row_begin, s.y_min), y_end = std::min(row_end, s.y_max + 1);
  for (int y = y_begin; y < y_end; ++y) {
    SegmentRow r;
    r.y = y;
    if (!RowSpan(s, y, width, &r.x_begin, &r.x_end)) continue;
    r.x_begin = std::max(r.x_begin, frame_view.rows[y][0]);
    r.x_end = std::min(r.x_end, frame_view.rows[y][1] + 1);
    if (r.x_begin >= r.x_end) continue;
    const float fy = static_cast<float>(y);
    // Homogeneous source coordinates and inverse depth, linear along the row.
    r.hx0 = h[1] * fy + h[2];
    r.hy0 = h[4] * fy + h[5];
    r.hw0 = h[7] * fy + h[8];
    r.iz0 = s.inv_depth[1] * fy + s.inv_depth[2];
    row(r);
  }
}

// Calls emit(x, y, slot, alpha, bgr_premultiplied, z) for every fragment of setup `s` of `view` in
// rows [row_begin, row_end) whose pixel holds the view (`frame_view`) in a slot. `skip(x, y, slot)`
// is asked first, before any sampling (a saturated pixel needs no more fragments). bgr is null
// when with_colour is false.
template <typename Skip, typename Emit>
inline void RasterizeSegment(const SceneView& view,
                             const FrameView& frame_view,
                             const SegmentSetup& s,
                             const std::vector<ViewSlots>& slots,
                             int width,
                             int row_begin,
                             int row_end,
                             bool with_colour,
                             Skip&& skip,
                             Emit&& emit) {
  const int view_index = frame_view.view;
  const SceneSegment& segment = view.segments[s.segment];
  ForEachSegmentRow(frame_view, s, width, row_begin, row_end, [&](const SegmentRow& r) {
    const int y = r.y;
    const ViewSlots* slot_row = slots.data() + static_cast<size_t>(y) * width;
    for (int x = r.x_begin; x < r.x_end; ++x) {
      const int slot = SlotOf(slot_row[x], view_index);
      if (slot < 0 || skip(x, y, slot)) continue;
      const float fx = static_cast<float>(x);
      float u, v;
      if (!FragmentSource(s, segment, r, fx, &u, &v)) continue;
      float bgr[3] = {0, 0, 0};
      float alpha = SampleSegment(view, s.segment, u, v, bgr);
      if (s.texture_weight < 1.0f) {  // stretched (texture_stretch.h)
        alpha *= s.texture_weight;
        for (float& c : bgr) c *= s.texture_weight;
      }
      if (alpha <= 1e-6f) continue;
      const float inv_z = s.inv_depth[0] * fx + r.iz0;
      if (!(inv_z > 0)) continue;
      emit(x, y, slot, alpha, with_colour ? bgr : nullptr, 1.0f / inv_z);
    }
  });
}

}  // namespace px::render
