// Segments as textured rectangles in a novel camera (ALGORITHM.md section 4): per frame, each drawn
// segment's projected rectangle, its novel-pixel -> source-pixel homography and its inverse depth
// in the novel camera, sorted front to back per view; per fragment, the masked bilinear sample of
// the segment images. Shared by the preview and offline compositors and by Coverage().
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/core/hal/intrin.hpp>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/render/layered_scene.h"
#include "pipeline/render/texture_stretch.h"
#include "pipeline/render/view_mesh.h"

namespace px::render {

// Where one segment lands in the novel camera this frame.
struct SegmentSetup {
  int32_t segment = 0;                               // index in its SceneView
  float key = 0;                                     // novel depth of its centre (front-to-back order)
  int x_min = 0, x_max = -1, y_min = 0, y_max = -1;  // pixel bounds, clipped to its view's region
  std::array<std::array<float, 2>, 4> corners{};     // projected rectangle corners, novel pixels
  std::array<float, 9> homography{};                 // row-major, novel pixel (x, y, 1) -> source pixel
  std::array<float, 3> inv_depth{};                  // 1/z in the novel camera = a x + b y + c
  float texture_weight = 1;                          // its fragments' alpha scale (texture_stretch.h), (0, 1]
};

// One view drawn this frame: the output pixels that hold it in a slot, and its segments.
struct FrameView {
  int view = 0;                          // index in LayeredScene::views() (= the mesh's view)
  cv::Rect region;                       // bounding box of the pixels holding it in a slot
  std::vector<std::array<int, 2>> rows;  // per output row: first and last x holding it (empty: x0 > x1)
  double weight_sum = 0;                 // its viewing weight summed over the frame
  bool blends = false;                   // some pixel may blend it (a slot other than a witness's)
  bool witnesses = false;                // some pixel holds it as its witness (ViewSlots)
  std::vector<SegmentSetup> segments;    // front to back
};

// The views the slots refer to and their segments, set up for one frame (parallel over views'
// segments) into `frame_views`, whose storage is reused from the previous frame (a frame sets up
// tens of thousands of segments). Views never referenced are absent. Segments stretched beyond
// `stretch.fade_to` are culled, those beyond fade_from carry their texture_weight. Witness slots
// (ViewSlots) count only `with_witnesses` (the preview's colour consensus votes with them; a
// view that is only a witness costs the set-up of all its segments).
void SetUpFrame(const LayeredScene& scene,
                const CameraModel& camera,
                const Rigid3& cam_from_world,
                const std::vector<ViewSlots>& slots,
                const TextureStretchOptions& stretch,
                bool with_witnesses,
                std::vector<FrameView>* frame_views);

// Pixels [*x_begin, *x_end) of row y whose centres lie in the segment's projected rectangle,
// clipped to [0, width). False when none.
inline bool RowSpan(const SegmentSetup& s, int y, int width, int* x_begin, int* x_end) {
  const float fy = static_cast<float>(y);
  float lo = INFINITY, hi = -INFINITY;
  for (int k = 0; k < 4; ++k) {
    const auto& a = s.corners[k];
    const auto& b = s.corners[(k + 1) & 3];
    const float y_lo = std::min(a[1], b[1]), y_hi = std::max(a[1], b[1]);
    if (fy < y_lo || fy > y_hi) continue;
    float x;
    if (b[1] == a[1]) {
      lo = std::min(lo, std::min(a[0], b[0]));
      hi = std::max(hi, std::max(a[0], b[0]));
      continue;
    }
    x = a[0] + (fy - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  if (!(lo <= hi)) return false;
  *x_begin = std::max({s.x_min, 0, static_cast<int>(std::ceil(lo))});
  *x_end = std::min({s.x_max + 1, width, static_cast<int>(std::floor(hi)) + 1});
  return *x_begin < *x_end;
}

// The masked bilinear sample of segment `segment` at source pixel (u, v), which must lie within
// one pixel of the image (the segment's rectangle does): (B, G, R, alpha) with the colour
// premultiplied by alpha (ALGORITHM.md section 4). Texels beyond the image are empty (the
// padding). One 4-lane multiply-add per texel layer holding the segment: the texel's constant 4th
// colour byte (1) sums the weights into the alpha lane.
inline cv::v_float32x4 SampleSegmentPremultiplied(const SceneView& view, int32_t segment, float u, float v) {
  // u, v >= -1 here, so truncating u + 1 floors it.
  const int iu = static_cast<int>(u + 1.0f) - 1, iv = static_cast<int>(v + 1.0f) - 1;
  const float fu = u - static_cast<float>(iu), fv = v - static_cast<float>(iv);
  const SegmentTexel* t00 = view.TexelPtr(iu, iv);
  const SegmentTexel* t01 = t00 + view.TexelStride();
  constexpr float kScale = 1.0f / SegmentTexel::kWeightScale;
  const float gu = (1.0f - fu) * kScale, hu = fu * kScale;
  const float beta[4] = {gu * (1.0f - fv), hu * (1.0f - fv), gu * fv, hu * fv};
  const SegmentTexel* const texels[4] = {t00, t00 + 1, t01, t01 + 1};
  cv::v_float32x4 sum = cv::v_setzero_f32();
  const auto add = [&](const SegmentTexel& t, int layer, float bilinear) {
    const cv::v_float32x4 bgr1 = cv::v_cvt_f32(cv::v_reinterpret_as_s32(cv::v_load_expand_q(t.colour[layer].data())));
    sum = sum + bgr1 * cv::v_setall_f32(bilinear * t.weight[layer]);
  };
  for (int i = 0; i < 4; ++i) {
    const SegmentTexel& t = *texels[i];
    if (t.segment[0] == segment) add(t, 0, beta[i]);
    if (t.segment[1] == segment) add(t, 1, beta[i]);
  }
  return sum;
}

// The same sample as alpha, its premultiplied colour added to `bgr`.
inline float SampleSegment(const SceneView& view, int32_t segment, float u, float v, float* bgr) {
  float lanes[4];
  cv::v_store(lanes, SampleSegmentPremultiplied(view, segment, u, v));
  bgr[0] += lanes[0];
  bgr[1] += lanes[1];
  bgr[2] += lanes[2];
  return lanes[3];
}

// The slot of pixel `slots` that holds `view`, or -1.
inline int SlotOf(const ViewSlots& slots, int view) {
  for (int k = 0; k < 3; ++k) {
    if (slots.view[k] == view) return k;
  }
  return -1;
}

// Row bands for parallel compositing: band b covers rows [b * kBandRows, (b + 1) * kBandRows).
// For each band, the (frame view, segment setup) pairs that touch it, each view's front to back.
constexpr int kBandRows = 16;
struct BandEntry {
  int32_t frame_view;
  int32_t setup;
};
std::vector<std::vector<BandEntry>> BinSegmentsIntoBands(const std::vector<FrameView>& frame_views, int height);

}  // namespace px::render
