// The preview: each view's segments composited front to back into its slot of the three rendering
// buffers, then the soft z-buffer across the slots (ALGORITHM.md sections 4 and 5).
//
// Speed: a band of rows keeps its rendering buffers in a per-thread buffer that stays in cache
// (slot-major planes of 4-lane cells, premultiplied B, G, R and alpha, plus a depth plane), a
// fragment is one 4-lane multiply-add per texel layer and one 4-lane add into its cell, and the
// resolve clears the cells it has read, so the next band (or frame) starts from zeros without a
// separate pass and nothing is allocated per frame.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <limits>

#include <opencv2/core/hal/intrin.hpp>

#include "pipeline/render/compositor.h"

namespace px::render {
namespace {

// Below this alpha a slot saw nothing.
constexpr float kSeenAlpha = 1e-4f;

// One band's three rendering buffers: cell (slot k, pixel p) is cells[4 (k pixels + p) ..] =
// premultiplied B, G, R, alpha, and depths[k pixels + p] its alpha-weighted depth. All zero
// between bands (the resolve clears what it reads).
struct BandBuffers {
  std::vector<float> cells;
  std::vector<float> depths;
  int pixels = 0;  // pixels per slot plane: rows * width of the current band layout

  void Reserve(int band_pixels) {
    pixels = band_pixels;
    const size_t needed = 3 * static_cast<size_t>(band_pixels);
    if (depths.size() < needed) {
      cells.assign(4 * needed, 0.0f);
      depths.assign(needed, 0.0f);
    }
  }
};

BandBuffers& ThreadBandBuffers() {
  thread_local BandBuffers buffers;
  return buffers;
}

// Segment `s` of frame view `fv` into the band's rendering buffers (ALGORITHM.md section 4):
// the same fragments, samples and saturating blend as RasterizeSegment + the preview's emit, with
// the per-row terms hoisted. Returns the fragments generated.
long CompositeSegment(const SceneView& view, const FrameView& fv, const SegmentSetup& s,
                      const std::vector<ViewSlots>& slots, int width, int row_begin, int row_end, bool with_colour,
                      BandBuffers* band) {
  const int view_index = fv.view;
  const SceneSegment& segment = view.segments[s.segment];
  float* cells = band->cells.data();
  float* depths = band->depths.data();
  const size_t plane = static_cast<size_t>(band->pixels);
  long fragments = 0;
  ForEachSegmentRow(fv, s, width, row_begin, row_end, [&](const SegmentRow& r) {
    const ViewSlots* slot_row = slots.data() + static_cast<size_t>(r.y) * width;
    // This row's cells and depth sums in each slot's plane.
    const size_t row_offset = static_cast<size_t>(r.y - row_begin) * width;
    float* const row_cells[3] = {cells + 4 * row_offset, cells + 4 * (plane + row_offset),
                                 cells + 4 * (2 * plane + row_offset)};
    float* const row_depths[3] = {depths + row_offset, depths + plane + row_offset, depths + 2 * plane + row_offset};
    for (int x = r.x_begin; x < r.x_end; ++x) {
      const int slot = SlotOf(slot_row[x], view_index);
      if (slot < 0) continue;
      float* cell = row_cells[slot] + 4 * x;
      if (cell[3] >= 1.0f) continue;  // saturated: nothing behind can add to it
      const float fx = static_cast<float>(x);
      float u, v;
      if (!FragmentSource(s, segment, r, fx, &u, &v)) continue;
      const cv::v_float32x4 sample = SampleSegmentPremultiplied(view, s.segment, u, v);
      const float alpha = cv::v_extract_n<3>(sample);
      if (alpha <= 1e-6f) continue;
      const float inv_z = s.inv_depth[0] * fx + r.iz0;
      if (!(inv_z > 0)) continue;
      const float z = 1.0f / inv_z;
      ++fragments;
      // Front to back, saturating (GL's SRC_ALPHA_SATURATE): the fragment adds min(alpha, 1 - A).
      const float f = std::min(alpha, 1.0f - cell[3]);
      if (f <= 0) continue;
      if (!with_colour) {
        cell[3] += f;
      } else if (f == alpha) {
        cv::v_store(cell, cv::v_load(cell) + sample);  // the whole sample: alpha lane += f
      } else {
        float scaled[4];
        cv::v_store(scaled, sample * cv::v_setall_f32(f / alpha));  // bgr is premultiplied by alpha
        scaled[3] = f;
        cv::v_store(cell, cv::v_load(cell) + cv::v_load(scaled));
      }
      row_depths[slot][x] += f * z;
    }
  });
  return fragments;
}

// The blended pixel from the soft z sums: `sum` = (sum b_k C_k, sum b_k A_k), sum_b = sum b_k,
// sum_w = sum w_k, sum_wz = sum w_k z_k. False (nothing written) when nothing was seen.
inline bool WriteBlend(const cv::v_float32x4& sum, float sum_b, float sum_w, float sum_wz, float* alpha, float* depth,
                       float* bgr) {
  const float sum_ba = cv::v_extract_n<3>(sum);
  if (!(sum_b > 0) || !(sum_ba > 0)) return false;
  *alpha = sum_ba / sum_b;
  *depth = sum_wz / sum_w;
  if (bgr != nullptr) {
    float lanes[4];
    cv::v_store(lanes, sum * cv::v_setall_f32(1.0f / sum_ba));
    bgr[0] = lanes[0];
    bgr[1] = lanes[1];
    bgr[2] = lanes[2];
  }
  return true;
}

// The soft z-buffer across one pixel's three slots (section 5): `cells[k]` is slot k's cell
// (premultiplied B, G, R, alpha), `depth_sums[k]` its alpha-weighted depth. Writes the blended
// alpha and depth, and the colour when `bgr` is not null. The slots taking part are a bit mask,
// and the usual pixel (three weighted views that all saw something) takes a branch-free path;
// the sums run over the slots in order either way, as the reference's loop adds them.
inline void ResolvePixel(const float* const cells[3], const float depth_sums[3], const ViewSlots& slots,
                         const SoftZ& soft_z, float* alpha, float* depth, float* bgr) {
  const float a0 = cells[0][3], a1 = cells[1][3], a2 = cells[2][3];
  if (slots.view[0] != ViewSlots::kNone && slots.view[1] != ViewSlots::kNone && slots.view[2] != ViewSlots::kNone &&
      a0 > kSeenAlpha && a1 > kSeenAlpha && a2 > kSeenAlpha && slots.weight[0] > 0 && slots.weight[1] > 0 &&
      slots.weight[2] > 0) {
    // The usual pixel: three weighted views that all saw something (tier 1 is all three).
    const float z0 = depth_sums[0] / a0, z1 = depth_sums[1] / a1, z2 = depth_sums[2] / a2;
    const float z_near = std::min(std::min(z0, z1), z2);
    const float w0 = soft_z.Weight(z0 - z_near), w1 = soft_z.Weight(z1 - z_near), w2 = soft_z.Weight(z2 - z_near);
    const float b0 = slots.weight[0] * w0, b1 = slots.weight[1] * w1, b2 = slots.weight[2] * w2;
    const float sum_b = b0 + b1 + b2, sum_w = w0 + w1 + w2, sum_wz = w0 * z0 + w1 * z1 + w2 * z2;
    const cv::v_float32x4 sum = cv::v_load(cells[0]) * cv::v_setall_f32(b0) +
                                cv::v_load(cells[1]) * cv::v_setall_f32(b1) +
                                cv::v_load(cells[2]) * cv::v_setall_f32(b2);
    if (WriteBlend(sum, sum_b, sum_w, sum_wz, alpha, depth, bgr)) return;
  }
  int seen = 0, weighted = 0;
  for (int k = 0; k < 3; ++k) {
    seen |= (slots.view[k] != ViewSlots::kNone && cells[k][3] > kSeenAlpha) << k;
    weighted |= (slots.weight[k] > 0) << k;
  }
  // Tier 1: the slots of weighted views that saw something; else every slot that saw something,
  // each weighing 1.
  int in = seen & weighted;
  const bool tier1 = in != 0;
  if (!tier1) in = seen;
  *alpha = 0;
  *depth = 0;
  if (bgr != nullptr) bgr[0] = bgr[1] = bgr[2] = 0;
  if (in == 0) return;
  float z[3], view_weight[3];
  float z_near = std::numeric_limits<float>::infinity();
  for (int k = 0; k < 3; ++k) {
    const bool taking_part = (in >> k) & 1;
    view_weight[k] = tier1 ? slots.weight[k] : 1.0f;
    z[k] = taking_part ? depth_sums[k] / cells[k][3] : 0.0f;
    if (taking_part) z_near = std::min(z_near, z[k]);
  }
  // (B, G, R, alpha) lanes sum b_k C_k and b_k A_k at once.
  cv::v_float32x4 sum = cv::v_setzero_f32();
  float sum_b = 0, sum_w = 0, sum_wz = 0;
  for (int k = 0; k < 3; ++k) {
    if (!((in >> k) & 1)) continue;
    const float w = soft_z.Weight(z[k] - z_near);
    const float b = view_weight[k] * w;
    sum_b += b;
    sum_w += w;
    sum_wz += w * z[k];
    sum = sum + cv::v_load(cells[k]) * cv::v_setall_f32(b);
  }
  WriteBlend(sum, sum_b, sum_w, sum_wz, alpha, depth, bgr);
}

// ResolvePixel for four pixels at once (x .. x + 3 of a row) when each has a tier-1 slot (a
// weighted view that saw something) and its tier-1 slots' depths lie within gamma of their
// nearest (soft z weight 1): `cells[k]` and `depth_sums[k]` point at slot k of pixel x, `slots` at
// pixel x's. Lane by lane the same operations in the same order as ResolvePixel, the slots not
// taking part adding exact zeros. False, with nothing written, when one of the four is not such
// a pixel.
inline bool ResolveFourUsualPixels(const float* const cells[3], const float* const depth_sums[3],
                                   const ViewSlots* slots, float gamma, float* alpha, float* depth, float* bgr) {
  using cv::v_float32x4;
  static_assert(sizeof(ViewSlots) == 16 && offsetof(ViewSlots, weight) == 4, "view bytes, then three weights");
  // Per slot: the four pixels' B, G, R, alpha and depth sums as lanes.
  v_float32x4 b[3], g[3], r[3], a[3], z[3];
  for (int k = 0; k < 3; ++k) {
    cv::v_transpose4x4(cv::v_load(cells[k]), cv::v_load(cells[k] + 4), cv::v_load(cells[k] + 8),
                       cv::v_load(cells[k] + 12), b[k], g[k], r[k], a[k]);
    z[k] = cv::v_load(depth_sums[k]);
  }
  const float* slot_words = reinterpret_cast<const float*>(slots);
  v_float32x4 views, w[3];
  cv::v_transpose4x4(cv::v_load(slot_words), cv::v_load(slot_words + 4), cv::v_load(slot_words + 8),
                     cv::v_load(slot_words + 12), views, w[0], w[1], w[2]);
  const cv::v_uint32x4 view_bytes = cv::v_reinterpret_as_u32(views), none = cv::v_setall_u32(ViewSlots::kNone);
  const v_float32x4 zero = cv::v_setzero_f32(), one = cv::v_setall_f32(1.0f), seen = cv::v_setall_f32(kSeenAlpha);
  const v_float32x4 infinity = cv::v_setall_f32(std::numeric_limits<float>::infinity());
  // Tier 1 per slot: a view, weighted, that saw something.
  v_float32x4 in[3];
  for (int k = 0; k < 3; ++k) {
    const cv::v_uint32x4 no_view = ((view_bytes >> (8 * k)) & none) == none;
    in[k] = cv::v_reinterpret_as_f32(~no_view) & (a[k] > seen) & (w[k] > zero);
  }
  if (!cv::v_check_all(in[0] | in[1] | in[2])) return false;
  v_float32x4 z_in[3], near = infinity;
  for (int k = 0; k < 3; ++k) {
    z[k] = cv::v_select(in[k], z[k] / a[k], zero);
    z_in[k] = cv::v_select(in[k], z[k], infinity);
    near = cv::v_select(z_in[k] < near, z_in[k], near);  // std::min over the slots, in order
  }
  const v_float32x4 gamma4 = cv::v_setall_f32(gamma);
  for (int k = 0; k < 3; ++k) {
    if (!cv::v_check_all(~in[k] | ((z[k] - near) <= gamma4))) return false;
  }
  // Soft z weights 1 where taking part, 0 elsewhere: b_k = v_k, w z_k = z_k.
  v_float32x4 v[3], count[3];
  for (int k = 0; k < 3; ++k) {
    v[k] = cv::v_select(in[k], w[k], zero);
    count[k] = cv::v_select(in[k], one, zero);
  }
  const v_float32x4 sum_b = v[0] + v[1] + v[2];
  const v_float32x4 sum_ba = a[0] * v[0] + a[1] * v[1] + a[2] * v[2];
  if (!cv::v_check_all((sum_b > zero) & (sum_ba > zero))) return false;
  cv::v_store(alpha, sum_ba / sum_b);
  cv::v_store(depth, (z[0] + z[1] + z[2]) / (count[0] + count[1] + count[2]));
  if (bgr != nullptr) {
    const v_float32x4 inv = one / sum_ba;
    cv::v_store_interleave(bgr, (b[0] * v[0] + b[1] * v[1] + b[2] * v[2]) * inv,
                           (g[0] * v[0] + g[1] * v[1] + g[2] * v[2]) * inv,
                           (r[0] * v[0] + r[1] * v[1] + r[2] * v[2]) * inv);
  }
  return true;
}

// Rows [row_begin, row_end) of the band resolved into `out`; the band's cells cleared.
void ResolveBand(const std::vector<ViewSlots>& slots, const SoftZ& soft_z, int width, int row_begin, int row_end,
                 bool with_colour, BandBuffers* band, FrameComposite* out) {
  float* cells = band->cells.data();
  float* depths = band->depths.data();
  const size_t plane = static_cast<size_t>(band->pixels);
  const cv::v_float32x4 zero = cv::v_setzero_f32();
  for (int y = row_begin; y < row_end; ++y) {
    const ViewSlots* slot_row = slots.data() + static_cast<size_t>(y) * width;
    float* alpha_row = out->alpha.ptr<float>(y);
    float* depth_row = out->depth.ptr<float>(y);
    float* colour_row = with_colour ? out->colour.ptr<float>(y) : nullptr;
    const size_t row_offset = static_cast<size_t>(y - row_begin) * width;
    // Four pixels at a time; a group with an unusual pixel (or the row's last few) one by one.
    for (int x0 = 0; x0 < width; x0 += 4) {
      const int x1 = std::min(width, x0 + 4);
      const size_t first = row_offset + x0;
      const float* const group[3] = {cells + 4 * first, cells + 4 * (plane + first), cells + 4 * (2 * plane + first)};
      const float* const group_depths[3] = {depths + first, depths + plane + first, depths + 2 * plane + first};
      if (x1 - x0 < 4 ||
          !ResolveFourUsualPixels(group, group_depths, slot_row + x0, soft_z.gamma(), alpha_row + x0, depth_row + x0,
                                  colour_row != nullptr ? colour_row + 3 * x0 : nullptr)) {
        for (int x = x0; x < x1; ++x) {
          const size_t index = row_offset + x;
          const float* const cell[3] = {cells + 4 * index, cells + 4 * (plane + index), cells + 4 * (2 * plane + index)};
          const float sums[3] = {depths[index], depths[plane + index], depths[2 * plane + index]};
          ResolvePixel(cell, sums, slot_row[x], soft_z, alpha_row + x, depth_row + x,
                       colour_row != nullptr ? colour_row + 3 * x : nullptr);
        }
      }
      for (int k = 0; k < 3; ++k) {
        float* const cell = cells + 4 * (k * plane + first);
        for (int i = 0; i < x1 - x0; ++i) {
          cv::v_store(cell + 4 * i, zero);
          depths[k * plane + first + i] = 0.0f;
        }
      }
    }
  }
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
    BandBuffers& band = ThreadBandBuffers();
    band.Reserve(kBandRows * width);
    long count = 0;
    for (int b = range.start; b < range.end; ++b) {
      const int row_begin = b * kBandRows, row_end = std::min(height, row_begin + kBandRows);
      for (const BandEntry& entry : bands[b]) {
        const FrameView& fv = frame_views[entry.frame_view];
        count += CompositeSegment(scene.views()[fv.view], fv, fv.segments[entry.setup], slots, width, row_begin,
                                  row_end, with_colour, &band);
      }
      ResolveBand(slots, soft_z, width, row_begin, row_end, with_colour, &band, out);
    }
    fragments += count;
  });
  out->fragments = fragments;
}

}  // namespace px::render
