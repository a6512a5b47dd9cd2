// The preview: each view's segments composited front to back into its slot of the three rendering
// buffers, then the soft z-buffer across the slots (ALGORITHM.md sections 4 and 5).
#include <algorithm>
#include <atomic>
#include <limits>

#include "pipeline/render/compositor.h"

namespace px::render {
namespace {

// Below this alpha a slot saw nothing.
constexpr float kSeenAlpha = 1e-4f;
// Per pixel and slot: premultiplied B, G, R, alpha, alpha-weighted depth.
constexpr int kCell = 5;
constexpr int kPixelFloats = 3 * kCell;

struct Resolved {
  float bgr[3] = {0, 0, 0};
  float alpha = 0;
  float depth = 0;
};

// The soft z-buffer across one pixel's slots (section 5).
inline Resolved ResolveSlots(const float* cells, const ViewSlots& slots, const SoftZ& soft_z, bool with_colour) {
  Resolved out;
  float z[3], view_weight[3];
  bool seen[3];
  bool tier1 = false;
  for (int k = 0; k < 3; ++k) {
    const float a = cells[k * kCell + 3];
    seen[k] = slots.view[k] != ViewSlots::kNone && a > kSeenAlpha;
    z[k] = seen[k] ? cells[k * kCell + 4] / a : 0.0f;
    view_weight[k] = slots.weight[k];
    tier1 = tier1 || (seen[k] && view_weight[k] > 0);
  }
  bool any = false;
  for (int k = 0; k < 3; ++k) {
    if (!seen[k]) continue;
    if (tier1 && !(view_weight[k] > 0)) {
      seen[k] = false;
    } else if (!tier1) {
      view_weight[k] = 1.0f;
    }
    any = any || seen[k];
  }
  if (!any) return out;
  float z_near = std::numeric_limits<float>::infinity();
  for (int k = 0; k < 3; ++k) {
    if (seen[k]) z_near = std::min(z_near, z[k]);
  }
  float sum_b = 0, sum_ba = 0, sum_w = 0, sum_wz = 0;
  float bgr[3] = {0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    if (!seen[k]) continue;
    const float w = soft_z.Weight(z[k] - z_near);
    const float b = view_weight[k] * w;
    const float* cell = cells + k * kCell;
    sum_b += b;
    sum_ba += b * cell[3];
    sum_w += w;
    sum_wz += w * z[k];
    if (with_colour) {
      bgr[0] += b * cell[0];
      bgr[1] += b * cell[1];
      bgr[2] += b * cell[2];
    }
  }
  if (!(sum_b > 0) || !(sum_ba > 0)) return out;
  out.alpha = sum_ba / sum_b;
  out.depth = sum_wz / sum_w;
  if (with_colour) {
    const float inv = 1.0f / sum_ba;
    for (int c = 0; c < 3; ++c) out.bgr[c] = bgr[c] * inv;
  }
  return out;
}

}  // namespace

void CompositePreview(const LayeredScene& scene, const std::vector<FrameView>& frame_views,
                      const std::vector<ViewSlots>& slots, int width, int height, bool with_colour,
                      FrameComposite* out) {
  if (with_colour) {
    out->colour.create(height, width, CV_32FC3);
  } else {
    out->colour.release();
  }
  out->alpha.create(height, width, CV_32F);
  out->depth.create(height, width, CV_32F);
  const std::vector<std::vector<BandEntry>> bands = BinSegmentsIntoBands(frame_views, height);
  const SoftZ& soft_z = scene.soft_z();
  std::atomic<long> fragments{0};
  cv::parallel_for_(cv::Range(0, static_cast<int>(bands.size())), [&](const cv::Range& range) {
    std::vector<float> buffer;
    long count = 0;
    for (int band = range.start; band < range.end; ++band) {
      const int row_begin = band * kBandRows, row_end = std::min(height, row_begin + kBandRows);
      buffer.assign(static_cast<size_t>(row_end - row_begin) * width * kPixelFloats, 0.0f);
      for (const BandEntry& entry : bands[band]) {
        const FrameView& fv = frame_views[entry.frame_view];
        const SceneView& view = scene.views()[fv.view];
        RasterizeSegment(view, fv, fv.segments[entry.setup], slots, width, row_begin, row_end, with_colour,
                         [&](int x, int y, int slot) {
                           return buffer[(static_cast<size_t>(y - row_begin) * width + x) * kPixelFloats +
                                         slot * kCell + 3] >= 1.0f;
                         },
                         [&](int x, int y, int slot, float alpha, const float* bgr, float z) {
                           ++count;
                           float* cell = buffer.data() +
                                         (static_cast<size_t>(y - row_begin) * width + x) * kPixelFloats +
                                         slot * kCell;
                           // Front to back, saturating (GL's SRC_ALPHA_SATURATE).
                           const float f = std::min(alpha, 1.0f - cell[3]);
                           if (f <= 0) return;
                           if (bgr != nullptr) {
                             const float scale = f / alpha;  // bgr is premultiplied by alpha
                             cell[0] += scale * bgr[0];
                             cell[1] += scale * bgr[1];
                             cell[2] += scale * bgr[2];
                           }
                           cell[3] += f;
                           cell[4] += f * z;
                         });
      }
      for (int y = row_begin; y < row_end; ++y) {
        const ViewSlots* slot_row = slots.data() + static_cast<size_t>(y) * width;
        const float* cells = buffer.data() + static_cast<size_t>(y - row_begin) * width * kPixelFloats;
        float* alpha_row = out->alpha.ptr<float>(y);
        float* depth_row = out->depth.ptr<float>(y);
        cv::Vec3f* colour_row = with_colour ? out->colour.ptr<cv::Vec3f>(y) : nullptr;
        for (int x = 0; x < width; ++x) {
          const Resolved r = ResolveSlots(cells + static_cast<size_t>(x) * kPixelFloats, slot_row[x], soft_z,
                                          with_colour);
          alpha_row[x] = r.alpha;
          depth_row[x] = r.depth;
          if (colour_row != nullptr) colour_row[x] = cv::Vec3f(r.bgr[0], r.bgr[1], r.bgr[2]);
        }
      }
    }
    fragments += count;
  });
  out->fragments = fragments;
}

}  // namespace px::render
