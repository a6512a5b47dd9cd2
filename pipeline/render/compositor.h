// From segments to one blended image before hole filling: the preview's three rendering buffers
// with a soft z-buffer across them (ALGORITHM.md sections 4 and 5), and the offline soft z over
// all fragments of all contributing views (section 10). Both work in bands of rows in parallel.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/render/layered_scene.h"
#include "pipeline/render/segment_raster.h"
#include "pipeline/render/view_mesh.h"

namespace px::render {

struct FrameComposite {
  long fragments = 0;  // fragments generated (before compositing)
  cv::Mat colour;  // CV_32FC3, 0..255, un-premultiplied where alpha > 0 (empty: coverage only)
  cv::Mat alpha;   // CV_32F, the blended alpha: covered where >= RenderOptions::covered_alpha
  cv::Mat depth;   // CV_32F, z in the novel camera, 0 where alpha == 0
};

// `slots` are the frame's viewing weights (width * height), `frame_views` its set-up segments.
// with_colour = false skips colour (Coverage()).
void CompositePreview(const LayeredScene& scene, const std::vector<FrameView>& frame_views,
                      const std::vector<ViewSlots>& slots, int width, int height, bool with_colour,
                      FrameComposite* out);

void CompositeOffline(const LayeredScene& scene, const std::vector<FrameView>& frame_views,
                      const std::vector<ViewSlots>& slots, int width, int height, FrameComposite* out);

// Calls emit(x, y, slot, alpha, bgr_premultiplied, z) for every fragment of setup `s` of `view` in
// rows [row_begin, row_end) whose pixel holds the view (`frame_view`) in a slot. `skip(x, y, slot)`
// is asked first, before any sampling (a saturated pixel needs no more fragments). bgr is null
// when with_colour is false.
template <typename Skip, typename Emit>
inline void RasterizeSegment(const SceneView& view, const FrameView& frame_view, const SegmentSetup& s,
                             const std::vector<ViewSlots>& slots, int width, int row_begin, int row_end,
                             bool with_colour, Skip&& skip, Emit&& emit) {
  const int view_index = frame_view.view;
  const SceneSegment& segment = view.segments[s.segment];
  const float* h = s.homography.data();
  const int y_begin = std::max(row_begin, s.y_min), y_end = std::min(row_end, s.y_max + 1);
  for (int y = y_begin; y < y_end; ++y) {
    int x_begin = 0, x_end = 0;
    if (!RowSpan(s, y, width, &x_begin, &x_end)) continue;
    x_begin = std::max(x_begin, frame_view.rows[y][0]);
    x_end = std::min(x_end, frame_view.rows[y][1] + 1);
    const float fy = static_cast<float>(y);
    const ViewSlots* slot_row = slots.data() + static_cast<size_t>(y) * width;
    // Homogeneous source coordinates and inverse depth, linear along the row.
    const float hx0 = h[1] * fy + h[2], hy0 = h[4] * fy + h[5], hw0 = h[7] * fy + h[8];
    const float iz0 = s.inv_depth[1] * fy + s.inv_depth[2];
    for (int x = x_begin; x < x_end; ++x) {
      const int slot = SlotOf(slot_row[x], view_index);
      if (slot < 0 || skip(x, y, slot)) continue;
      const float fx = static_cast<float>(x);
      const float hw = h[6] * fx + hw0;
      if (!(hw > 0)) continue;
      const float inv_w = 1.0f / hw;
      const float u = (h[0] * fx + hx0) * inv_w;
      const float v = (h[3] * fx + hy0) * inv_w;
      if (!(u >= segment.rect[0] && u <= segment.rect[2] && v >= segment.rect[1] && v <= segment.rect[3])) continue;
      float bgr[3] = {0, 0, 0};
      const float alpha = SampleSegment(view, s.segment, u, v, bgr);
      if (alpha <= 1e-6f) continue;
      const float inv_z = s.inv_depth[0] * fx + iz0;
      if (!(inv_z > 0)) continue;
      emit(x, y, slot, alpha, with_colour ? bgr : nullptr, 1.0f / inv_z);
    }
  }
}

}  // namespace px::render
