// The preview: each view's segments composited front to back into its slot of the three rendering
// buffers, then the soft z-buffer across the slots (ALGORITHM.md sections 4 and 5).
//
// Speed: a band of rows keeps its rendering buffers in a per-thread buffer that stays in cache
// (slot-major planes of 4-lane cells, premultiplied B, G, R and alpha, plus a depth plane), a
// fragment is one 4-lane multiply-add per texel layer and one 4-lane add into its cell, and the
// resolve clears the cells it has read, so the next band (or frame) starts from zeros without a
// separate pass and nothing is allocated per frame.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <limits>
#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "pipeline/render/compositor.h"

namespace px::render {
namespace {

// Below this alpha a slot saw nothing.
constexpr float kSeenAlpha = 1e-4f;

// One band's three rendering buffers: cell (slot k, pixel p) is cells[4 (k pixels + p) ..] =
// premultiplied B, G, R, alpha, and depths[k pixels + p] its alpha-weighted depth. All zero
// between bands (the resolve clears what it reads).
// With contradictions, contra[(2 k + m) pixels + p] is the alpha of slot k's fragments that the
// view in slot (k + 1 + m) mod 3 contradicts, and contested[p] = 1 where any is not 0.
struct BandBuffers {
  std::vector<float> cells;
  std::vector<float> depths;
  std::vector<float> contra;
  std::vector<uint8_t> contested;
  // Where the witness pass draws: per pixel of the band, 1 where its witness is wanted
  // (WitnessWanted); per row, the pixels [first, end) spanning those (empty: first >= end).
  std::vector<uint8_t> witness_wanted;
  std::vector<std::array<int, 2>> witness_span;
  int pixels = 0;  // pixels per slot plane: rows * width of the current band layout

  void Reserve(int band_pixels) {
    pixels = band_pixels;
    const size_t needed = 3 * static_cast<size_t>(band_pixels);
    if (depths.size() < needed) {
      cells.assign(4 * needed, 0.0f);
      depths.assign(needed, 0.0f);
      contra.assign(2 * needed, 0.0f);
      contested.assign(band_pixels, 0);
    }
  }
};

BandBuffers& ThreadBandBuffers() {
  thread_local BandBuffers buffers;
  return buffers;
}

// Whether a pixel's witness must be drawn: both other slots saw something and disagree in colour
// beyond `agree_levels` (else no vote can change the pixel, OutvotedYield). Their cells are final:
// witnesses are drawn after every blendable slot of the band.
inline bool WitnessWanted(const float* const row_cells[3], int x, int witness, float agree_levels) {
  const int a = (witness + 1) % 3, b = (witness + 2) % 3;
  const float* ca = row_cells[a] + 4 * x;
  const float* cb = row_cells[b] + 4 * x;
  if (!(ca[3] > kSeenAlpha) || !(cb[3] > kSeenAlpha)) return false;
  const float ia = 1.0f / ca[3], ib = 1.0f / cb[3];
  for (int c = 0; c < 3; ++c) {
    if (std::abs(ca[c] * ia - cb[c] * ib) > agree_levels) return true;
  }
  return false;
}

// Marks the pixels of the band [row_begin, row_end), its blendable slots drawn, whose witness is
// wanted (WitnessWanted; the witness pass draws only there and cannot change the answer: it
// writes the witness's slot, the test reads the other two), and spans them per row. The rows
// that hold one are [*first, *end); false when none does.
bool RowsWantingWitnesses(const std::vector<ViewSlots>& slots,
                          BandBuffers& band,
                          int width,
                          int row_begin,
                          int row_end,
                          float agree_levels,
                          int* first,
                          int* end) {
  const size_t plane = static_cast<size_t>(band.pixels);
  *first = row_end;
  *end = row_begin;
  band.witness_wanted.assign(static_cast<size_t>(row_end - row_begin) * width, 0);
  band.witness_span.assign(row_end - row_begin, {width, 0});
  for (int y = row_begin; y < row_end; ++y) {
    const ViewSlots* slot_row = slots.data() + static_cast<size_t>(y) * width;
    const size_t row_offset = static_cast<size_t>(y - row_begin) * width;
    const float* const row_cells[3] = {band.cells.data() + 4 * row_offset,
                                       band.cells.data() + 4 * (plane + row_offset),
                                       band.cells.data() + 4 * (2 * plane + row_offset)};
    uint8_t* wanted = band.witness_wanted.data() + row_offset;
    std::array<int, 2>& span = band.witness_span[y - row_begin];
    for (int x = 0; x < width; ++x) {
      if (slot_row[x].witness == ViewSlots::kNone || !WitnessWanted(row_cells, x, slot_row[x].witness, agree_levels))
        continue;
      wanted[x] = 1;
      span[0] = std::min(span[0], x);
      span[1] = x + 1;
    }
    if (span[0] >= span[1]) continue;
    *first = std::min(*first, y);
    *end = y + 1;
  }
  return *first < *end;
}

// Which fragments CompositeSegment draws: the blendable slots', or (after them) the witnesses'
// where they are wanted.
enum class SlotPass { kBlendable, kWitness };

// Segment `s` of frame view `fv`, rows [row_begin, row_end) of the band that starts at row
// `band_begin`, into the band's rendering buffers (ALGORITHM.md section 4): the same fragments,
// samples and saturating blend as RasterizeSegment + the preview's emit, with the per-row terms
// hoisted. Returns the fragments generated.
long CompositeSegment(const SceneView& view,
                      const FrameView& fv,
                      const SegmentSetup& s,
                      const std::vector<ViewSlots>& slots,
                      int width,
                      int band_begin,
                      int row_begin,
                      int row_end,
                      bool with_colour,
                      bool contradictions,
                      SlotPass pass,
                      BandBuffers* band) {
  const int view_index = fv.view;
  const SceneSegment& segment = view.segments[s.segment];
  float* cells = band->cells.data();
  float* depths = band->depths.data();
  const size_t plane = static_cast<size_t>(band->pixels);
  const bool witness_pass = pass == SlotPass::kWitness;
  // A witness's own contradictions are never asked (it is not blended).
  const bool check = contradictions && segment.contradicted && !witness_pass;
  const bool faded = s.texture_weight < 1.0f;  // stretched (texture_stretch.h)
  const cv::v_float32x4 fade = cv::v_setall_f32(s.texture_weight);
  long fragments = 0;
  ForEachSegmentRow(fv, s, width, row_begin, row_end, [&](const SegmentRow& r) {
    int x_begin = r.x_begin, x_end = r.x_end;
    if (witness_pass) {
      const std::array<int, 2>& span = band->witness_span[r.y - band_begin];
      x_begin = std::max(x_begin, span[0]);
      x_end = std::min(x_end, span[1]);
    }
    const ViewSlots* slot_row = slots.data() + static_cast<size_t>(r.y) * width;
    // This row's cells and depth sums in each slot's plane.
    const size_t row_offset = static_cast<size_t>(r.y - band_begin) * width;
    const uint8_t* witness_wanted = witness_pass ? band->witness_wanted.data() + row_offset : nullptr;
    float* const row_cells[3] = {
        cells + 4 * row_offset, cells + 4 * (plane + row_offset), cells + 4 * (2 * plane + row_offset)};
    float* const row_depths[3] = {depths + row_offset, depths + plane + row_offset, depths + 2 * plane + row_offset};
    for (int x = x_begin; x < x_end; ++x) {
      if (witness_pass && !witness_wanted[x]) continue;
      const int slot = SlotOf(slot_row[x], view_index);
      if (slot < 0) continue;
      const bool is_witness = slot == slot_row[x].witness;
      if (is_witness != witness_pass) continue;
      float* cell = row_cells[slot] + 4 * x;
      if (cell[3] >= 1.0f) continue;  // saturated: nothing behind can add to it
      const float fx = static_cast<float>(x);
      float u, v;
      if (!FragmentSource(s, segment, r, fx, &u, &v)) continue;
      cv::v_float32x4 sample = SampleSegmentPremultiplied(view, s.segment, u, v);
      if (faded) sample = sample * fade;
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
      if (!check) continue;
      // Which of the pixel's other views contradict this fragment's surface (contradictions.h).
      const uint16_t mask = view.ContradictedAt(s.segment, u, v);
      if (mask == 0) continue;
      for (int m = 0; m < 2; ++m) {
        const int other = (slot + 1 + m) % 3;
        const uint8_t other_view = slot_row[x].view[other];
        if (other_view == ViewSlots::kNone || other == slot_row[x].witness) continue;
        const int bit = view.neighbour_bit[other_view];
        if (bit < 0 || !((mask >> bit) & 1)) continue;
        band->contra[(2 * slot + m) * plane + row_offset + x] += f;
        band->contested[row_offset + x] = 1;
      }
    }
  });
  return fragments;
}

// The blended pixel from the soft z sums: `sum` = (sum b_k C_k, sum b_k A_k), sum_b = sum b_k,
// sum_w = sum w_k, sum_wz = sum w_k z_k. False (nothing written) when nothing was seen.
inline bool WriteBlend(
    const cv::v_float32x4& sum, float sum_b, float sum_w, float sum_wz, float* alpha, float* depth, float* bgr) {
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
inline void ResolvePixel(const float* const cells[3],
                         const float depth_sums[3],
                         const ViewSlots& slots,
                         const SoftZ& soft_z,
                         float* alpha,
                         float* depth,
                         float* bgr) {
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
  // Tier 1: the slots of weighted views that saw something; else every slot but a witness's that
  // saw something, each weighing 1.
  int in = seen & weighted;
  const bool tier1 = in != 0;
  if (!tier1) in = seen & slots.BlendableBits();
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

// One pixel's slots as the contested resolve sees them: which take part (ResolvePixel's tiers),
// their depths, viewing weights, un-premultiplied colours, and c_kj, the share of slot k's alpha
// that slot j's view contradicts (contradictions.h).
struct ContestedSlots {
  int in = 0;
  int seen = 0;  // the slots that saw something, blended or not (a witness): depth and colour set
  float z[3] = {0, 0, 0};
  float view_weight[3] = {0, 0, 0};
  float exponent = 1;
  mutable float powered[3] = {-1, -1, -1};  // view_weight^exponent, computed when first needed
  float colour[3][3] = {};
  float contradicted[3][3] = {};

  bool TakesPart(int k) const { return ((in >> k) & 1) != 0; }
  // How much slot j outweighs slot k: v_j^e / (v_j^e + v_k^e).
  float Dominance(int j, int k) const {
    const float pj = Powered(j), pk = Powered(k);
    return pj + pk > 0 ? pj / (pj + pk) : 0.5f;
  }
  float Powered(int k) const {
    if (powered[k] < 0) powered[k] = std::pow(view_weight[k], exponent);
    return powered[k];
  }
  float ColourDistance(int j, int k) const {
    float largest = 0;
    for (int c = 0; c < 3; ++c) largest = std::max(largest, std::abs(colour[j][c] - colour[k][c]));
    return largest;
  }
};

// Trust t_k = 1 - max_j t_j c_kj d_jk, two rounds from t = 1 (a slot contradicted only by a slot
// that is itself distrusted keeps its trust).
void Trust(const ContestedSlots& p, const float (&contradicted)[3][3], float trust[3]) {
  trust[0] = trust[1] = trust[2] = 1;
  for (int round = 0; round < 2; ++round) {
    float next[3] = {1, 1, 1};
    for (int k = 0; k < 3; ++k) {
      if (!p.TakesPart(k)) continue;
      float suppressed = 0;
      for (int j = 0; j < 3; ++j) {
        if (j != k && p.TakesPart(j))
          suppressed = std::max(suppressed, trust[j] * contradicted[k][j] * p.Dominance(j, k));
      }
      next[k] = 1.0f - suppressed;
    }
    std::copy(next, next + 3, trust);
  }
}

// How far apart slots j and k are in colour, 0 (within colour_agree_levels) to 1 (from
// colour_apart_levels on), times the soft z weight of their depth difference: two images of one
// place only when close in depth.
float ColourApart(const ContestedSlots& p, int j, int k, const SoftZ& soft_z, const BlendRules& rules) {
  const float span = rules.colour_apart_levels - rules.colour_agree_levels;
  return std::clamp((p.ColourDistance(j, k) - rules.colour_agree_levels) / span, 0.0f, 1.0f) *
         soft_z.Weight(std::abs(p.z[j] - p.z[k]));
}

// A blended slot whose colour both other slots contradict while they agree with each other is
// outvoted: it yields whatever its weight (the one view that moved, or whose depth is off there),
// instead of sharing the pixel by weight with the two that agree. The other two may include a
// witness (ViewSlots: seen, not blended), which settles a disagreement between two blended views.
// `apart` holds the blended slots' disagreements; a witness's are its colour's against theirs.
// Whether it lowered a slot's trust.
bool OutvotedYield(
    const ContestedSlots& p, const float (&apart)[3][3], const SoftZ& soft_z, const BlendRules& rules, float trust[3]) {
  if (p.seen != 7) return false;
  bool lowered = false;
  const auto disagree = [&](int k, int j) {
    if (p.TakesPart(k) && p.TakesPart(j)) return std::max(apart[k][j], apart[j][k]);
    return ColourApart(p, j, k, soft_z, rules);
  };
  for (int k = 0; k < 3; ++k) {
    if (!p.TakesPart(k)) continue;
    const int a = (k + 1) % 3, b = (k + 2) % 3;
    const float against = std::min(disagree(k, a), disagree(k, b));
    const float others_agree = 1.0f - disagree(a, b);
    const float outvoted = 1.0f - against * others_agree;
    if (outvoted < trust[k]) {
      trust[k] = outvoted;
      lowered = true;
    }
  }
  return lowered;
}

// The soft z across the slots with each slot's blend and depth weight multiplied by its trust,
// the nearest surface looked for among the slots trusted at least half (all when none is).
// Returns whether the pixel saw anything (else alpha, depth and colour stay 0); `share` gets each
// slot's part of the blended colour.
bool TrustedBlend(const float* const cells[3],
                  const ContestedSlots& p,
                  const float trust[3],
                  const SoftZ& soft_z,
                  float* alpha,
                  float* depth,
                  float* bgr,
                  float share[3]) {
  float z_near = std::numeric_limits<float>::infinity();
  for (int k = 0; k < 3; ++k) {
    if (p.TakesPart(k) && trust[k] >= 0.5f) z_near = std::min(z_near, p.z[k]);
  }
  if (!std::isfinite(z_near)) {
    for (int k = 0; k < 3; ++k) {
      if (p.TakesPart(k)) z_near = std::min(z_near, p.z[k]);
    }
  }
  cv::v_float32x4 sum = cv::v_setzero_f32();
  float sum_b = 0, sum_w = 0, sum_wz = 0, blend[3] = {0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    if (!p.TakesPart(k)) continue;
    const float w = soft_z.Weight(p.z[k] - z_near) * trust[k];
    blend[k] = p.view_weight[k] * w;
    sum_b += blend[k];
    sum_w += w;
    sum_wz += w * p.z[k];
    sum = sum + cv::v_load(cells[k]) * cv::v_setall_f32(blend[k]);
  }
  *alpha = *depth = 0;
  if (bgr != nullptr) bgr[0] = bgr[1] = bgr[2] = 0;
  if (!WriteBlend(sum, sum_b, sum_w, sum_wz, alpha, depth, bgr)) return false;
  const float sum_ba = cv::v_extract_n<3>(sum);
  for (int k = 0; k < 3; ++k) share[k] = p.TakesPart(k) ? blend[k] * cells[k][3] / sum_ba : 0.0f;
  return true;
}

// Whether a blend with these shares shows a double image: a slot of at least a fifth of the colour
// whose colour differs by more than rules.double_image_levels from another slot's that also has a
// fifth, or that outweighs it and contradicts at least half of its alpha.
bool ShowsDoubleImage(const ContestedSlots& p, const float share[3], const BlendRules& rules) {
  constexpr float kVisibleShare = 0.2f;
  for (int k = 0; k < 3; ++k) {
    if (!p.TakesPart(k) || share[k] < kVisibleShare) continue;
    for (int j = 0; j < 3; ++j) {
      if (j == k || !p.TakesPart(j) || p.ColourDistance(j, k) <= static_cast<float>(rules.double_image_levels))
        continue;
      const bool blended = share[j] >= kVisibleShare;
      const bool shown_against = p.view_weight[j] > p.view_weight[k] && p.contradicted[k][j] >= 0.5f;
      if (blended || shown_against) return true;
    }
  }
  return false;
}

// Where a contested pixel's colour consensus differs from its blend: the consensus result, kept
// aside until CompositePreview knows whether the pixel lies in a region of such pixels.
struct ConsensusOut {
  float* alpha;
  float* depth;
  float* bgr;
  // 0: the same as the blend; kConsensusDiffers, plus kConsensusDouble when the consensus shows a
  // double image and kBlendDouble when the blend does.
  uint8_t* mark;
  // The pixel from its most heavily weighted slot alone, and {outvoted view, that slot's view}.
  float* solo_alpha;
  float* solo_depth;
  float* solo_bgr;
  uint8_t* views;
};
constexpr uint8_t kConsensusDiffers = 1;
constexpr uint8_t kConsensusDouble = 2;
constexpr uint8_t kBlendDouble = 4;

// The resolve of a contested pixel (some slot's surface contradicted by another slot's view), of a
// pixel whose blended slots disagree in colour under the consistent blend, or of any pixel when
// double images are measured (ALGORITHM.md section 5): ResolvePixel's tiers and soft z with each
// slot's trust from the contradictions (Trust, TrustedBlend) into alpha, depth and bgr, and
// `double_image` (when not null) marked where that blend shows a double image. With the colour
// consensus on (rules.colour_apart_levels above colour_agree_levels), slots at close depths whose
// colours disagree count as contradicting each other too; where that changes the pixel, the
// result goes to `consensus` instead (when not null).
void ResolveContestedPixel(const float* const cells[3],
                           const float depth_sums[3],
                           const float* contra,
                           const ViewSlots& slots,
                           const SoftZ& soft_z,
                           const BlendRules& rules,
                           float* alpha,
                           float* depth,
                           float* bgr,
                           uint8_t* double_image,
                           const ConsensusOut* consensus) {
  ContestedSlots p;
  int seen = 0, weighted = 0;
  for (int k = 0; k < 3; ++k) {
    seen |= (slots.view[k] != ViewSlots::kNone && cells[k][3] > kSeenAlpha) << k;
    weighted |= (slots.weight[k] > 0) << k;
  }
  p.in = seen & weighted;
  p.seen = seen;
  const bool tier1 = p.in != 0;
  if (!tier1) p.in = seen & slots.BlendableBits();
  *alpha = *depth = 0;
  if (bgr != nullptr) bgr[0] = bgr[1] = bgr[2] = 0;
  if (double_image != nullptr) *double_image = 0;
  if (consensus != nullptr) *consensus->mark = 0;
  if (p.in == 0) return;
  for (int k = 0; k < 3; ++k) {
    p.view_weight[k] = tier1 ? slots.weight[k] : 1.0f;
    if (!((seen >> k) & 1)) continue;
    p.z[k] = depth_sums[k] / cells[k][3];
    for (int c = 0; c < 3; ++c) p.colour[k][c] = cells[k][c] / cells[k][3];
    if (contra == nullptr || !p.TakesPart(k)) continue;
    for (int m = 0; m < 2; ++m) p.contradicted[k][(k + 1 + m) % 3] = std::min(1.0f, contra[2 * k + m] / cells[k][3]);
  }
  p.exponent = rules.dominance_exponent;
  float trust[3] = {1, 1, 1}, share[3];
  if (rules.consistent && contra != nullptr) Trust(p, p.contradicted, trust);
  if (!TrustedBlend(cells, p, trust, soft_z, alpha, depth, bgr, share)) return;
  const bool blend_double = (double_image != nullptr || consensus != nullptr) && ShowsDoubleImage(p, share, rules);
  if (double_image != nullptr && blend_double) *double_image = 255;
  if (!rules.consistent || consensus == nullptr || !(rules.colour_apart_levels > rules.colour_agree_levels)) return;
  // The colour consensus: slots the soft z would blend (close in depth) whose colours disagree
  // beyond noise show two images of one place; the lighter view yields as if contradicted.
  float apart[3][3];
  std::copy(&p.contradicted[0][0], &p.contradicted[0][0] + 9, &apart[0][0]);
  bool differs = false;
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 3; ++j) {
      if (j == k || !p.TakesPart(j) || !p.TakesPart(k)) continue;
      const float level = ColourApart(p, j, k, soft_z, rules);
      if (level > apart[k][j]) {
        apart[k][j] = level;
        differs = true;
      }
    }
  }
  // With no colour disagreement, a vote can change the pixel only through a contradiction or a
  // witness (most pixels here have neither: skip the work).
  if (!differs && contra == nullptr && (p.seen & ~p.in) == 0) return;
  Trust(p, apart, trust);
  const bool outvoted = OutvotedYield(p, apart, soft_z, rules, trust);
  if (!differs && !outvoted) return;
  if (!TrustedBlend(cells, p, trust, soft_z, consensus->alpha, consensus->depth, consensus->bgr, share)) return;
  *consensus->mark = kConsensusDiffers | (blend_double ? kBlendDouble : 0) |
                     (ShowsDoubleImage(p, share, rules) ? kConsensusDouble : 0);
  if (consensus->views == nullptr) return;
  // Which view the vote turned down (the least trusted, when below half) and which would draw the
  // pixel alone (the most heavily weighted): TakeRegionalConsensus weighs them region by region.
  int outvoted_slot = -1, heaviest = -1;
  for (int k = 0; k < 3; ++k) {
    if (!p.TakesPart(k)) continue;
    if (trust[k] < 0.5f && (outvoted_slot < 0 || trust[k] < trust[outvoted_slot])) outvoted_slot = k;
    if (heaviest < 0 || p.view_weight[k] > p.view_weight[heaviest]) heaviest = k;
  }
  consensus->views[0] = outvoted_slot < 0 ? ViewSlots::kNone : slots.view[outvoted_slot];
  consensus->views[1] = slots.view[heaviest];
  float alone[3] = {0, 0, 0};
  alone[heaviest] = 1;
  float alone_share[3];
  if (!TrustedBlend(
          cells, p, alone, soft_z, consensus->solo_alpha, consensus->solo_depth, consensus->solo_bgr, alone_share))
    consensus->views[1] = ViewSlots::kNone;
}

// ResolvePixel for four pixels at once (x .. x + 3 of a row) when each has a tier-1 slot (a
// weighted view that saw something) and its tier-1 slots' depths lie within gamma of their
// nearest (soft z weight 1): `cells[k]` and `depth_sums[k]` point at slot k of pixel x, `slots` at
// pixel x's. Lane by lane the same operations in the same order as ResolvePixel, the slots not
// taking part adding exact zeros. False, with nothing written, when one of the four is not such
// a pixel.
inline bool ResolveFourUsualPixels(const float* const cells[3],
                                   const float* const depth_sums[3],
                                   const ViewSlots* slots,
                                   float gamma,
                                   float agree_levels,
                                   float* alpha,
                                   float* depth,
                                   float* bgr) {
  using cv::v_float32x4;
  static_assert(sizeof(ViewSlots) == 16 && offsetof(ViewSlots, weight) == 4, "view bytes, then three weights");
  // Per slot: the four pixels' B, G, R, alpha and depth sums as lanes.
  v_float32x4 b[3], g[3], r[3], a[3], z[3];
  for (int k = 0; k < 3; ++k) {
    cv::v_transpose4x4(cv::v_load(cells[k]),
                       cv::v_load(cells[k] + 4),
                       cv::v_load(cells[k] + 8),
                       cv::v_load(cells[k] + 12),
                       b[k],
                       g[k],
                       r[k],
                       a[k]);
    z[k] = cv::v_load(depth_sums[k]);
  }
  const float* slot_words = reinterpret_cast<const float*>(slots);
  v_float32x4 views, w[3];
  cv::v_transpose4x4(cv::v_load(slot_words),
                     cv::v_load(slot_words + 4),
                     cv::v_load(slot_words + 8),
                     cv::v_load(slot_words + 12),
                     views,
                     w[0],
                     w[1],
                     w[2]);
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
  if (agree_levels > 0) {
    // The consistent blend: slots whose colours disagree beyond agree_levels are resolved one by one.
    v_float32x4 colour[3][3];
    for (int k = 0; k < 3; ++k) {
      const v_float32x4 inv = cv::v_select(in[k], one / a[k], zero);
      colour[k][0] = b[k] * inv;
      colour[k][1] = g[k] * inv;
      colour[k][2] = r[k] * inv;
    }
    const v_float32x4 levels = cv::v_setall_f32(agree_levels);
    for (int k = 0; k < 3; ++k) {
      for (int j = k + 1; j < 3; ++j) {
        const v_float32x4 both = in[k] & in[j];
        for (int c = 0; c < 3; ++c) {
          if (cv::v_check_any(both & (cv::v_abs(colour[k][c] - colour[j][c]) > levels))) return false;
        }
      }
    }
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
    cv::v_store_interleave(bgr,
                           (b[0] * v[0] + b[1] * v[1] + b[2] * v[2]) * inv,
                           (g[0] * v[0] + g[1] * v[1] + g[2] * v[2]) * inv,
                           (r[0] * v[0] + r[1] * v[1] + r[2] * v[2]) * inv);
  }
  return true;
}

// Rows [row_begin, row_end) of the band resolved into `out`; the band's cells cleared. `rules`
// null: no pixel is contested.
void ResolveBand(const std::vector<ViewSlots>& slots,
                 const SoftZ& soft_z,
                 int width,
                 int row_begin,
                 int row_end,
                 bool with_colour,
                 const BlendRules* rules,
                 BandBuffers* band,
                 FrameComposite* out) {
  float* cells = band->cells.data();
  float* depths = band->depths.data();
  float* contra = band->contra.data();
  uint8_t* contested = band->contested.data();
  const size_t plane = static_cast<size_t>(band->pixels);
  const cv::v_float32x4 zero = cv::v_setzero_f32();
  const bool measure = rules != nullptr && rules->measure_double_images;
  const bool consistent = rules != nullptr && rules->consistent;
  const float agree_levels = consistent ? rules->colour_agree_levels : 0.0f;
  for (int y = row_begin; y < row_end; ++y) {
    const ViewSlots* slot_row = slots.data() + static_cast<size_t>(y) * width;
    float* alpha_row = out->alpha.ptr<float>(y);
    float* depth_row = out->depth.ptr<float>(y);
    float* colour_row = with_colour ? out->colour.ptr<float>(y) : nullptr;
    uint8_t* double_row = measure ? out->double_image.ptr<uint8_t>(y) : nullptr;
    const size_t row_offset = static_cast<size_t>(y - row_begin) * width;
    // Where the colour consensus changes a pixel, its result waits aside (CompositePreview).
    const bool with_consensus = consistent && with_colour && !out->consensus_mark.empty();
    const bool one_view = with_consensus && !out->consensus_views.empty();
    const auto consensus_at = [&](int x) {
      if (!with_consensus) return ConsensusOut{};
      return ConsensusOut{out->consensus_alpha.ptr<float>(y) + x,
                          out->consensus_depth.ptr<float>(y) + x,
                          out->consensus_colour.ptr<float>(y) + 3 * x,
                          out->consensus_mark.ptr<uint8_t>(y) + x,
                          one_view ? out->solo_alpha.ptr<float>(y) + x : nullptr,
                          one_view ? out->solo_depth.ptr<float>(y) + x : nullptr,
                          one_view ? out->solo_colour.ptr<float>(y) + 3 * x : nullptr,
                          one_view ? out->consensus_views.ptr<uint8_t>(y) + 2 * x : nullptr};
    };
    uint8_t* mark_row = with_consensus ? out->consensus_mark.ptr<uint8_t>(y) : nullptr;
    // Four pixels at a time; a group with an unusual pixel (or the row's last few) one by one.
    for (int x0 = 0; x0 < width; x0 += 4) {
      const int x1 = std::min(width, x0 + 4);
      const size_t first = row_offset + x0;
      const float* const group[3] = {cells + 4 * first, cells + 4 * (plane + first), cells + 4 * (2 * plane + first)};
      const float* const group_depths[3] = {depths + first, depths + plane + first, depths + 2 * plane + first};
      bool contested_group = false;
      for (int x = x0; x < x1 && rules != nullptr; ++x) contested_group = contested_group || contested[row_offset + x];
      if (measure || contested_group) {
        for (int x = x0; x < x1; ++x) {
          const size_t index = row_offset + x;
          const float* const cell[3] = {
              cells + 4 * index, cells + 4 * (plane + index), cells + 4 * (2 * plane + index)};
          const float sums[3] = {depths[index], depths[plane + index], depths[2 * plane + index]};
          float contra_sums[6];
          const bool is_contested = contested[index] != 0;
          if (is_contested) {
            for (int i = 0; i < 6; ++i) {
              contra_sums[i] = contra[i * plane + index];
              contra[i * plane + index] = 0.0f;
            }
            contested[index] = 0;
          }
          const ConsensusOut consensus = consensus_at(x);
          ResolveContestedPixel(cell,
                                sums,
                                is_contested ? contra_sums : nullptr,
                                slot_row[x],
                                soft_z,
                                *rules,
                                alpha_row + x,
                                depth_row + x,
                                colour_row != nullptr ? colour_row + 3 * x : nullptr,
                                double_row != nullptr ? double_row + x : nullptr,
                                with_consensus ? &consensus : nullptr);
        }
      } else if (x1 - x0 == 4 && ResolveFourUsualPixels(group,
                                                        group_depths,
                                                        slot_row + x0,
                                                        soft_z.gamma(),
                                                        agree_levels,
                                                        alpha_row + x0,
                                                        depth_row + x0,
                                                        colour_row != nullptr ? colour_row + 3 * x0 : nullptr)) {
        if (mark_row != nullptr) std::fill(mark_row + x0, mark_row + x1, uint8_t{0});
      } else {
        for (int x = x0; x < x1; ++x) {
          const size_t index = row_offset + x;
          const float* const cell[3] = {
              cells + 4 * index, cells + 4 * (plane + index), cells + 4 * (2 * plane + index)};
          const float sums[3] = {depths[index], depths[plane + index], depths[2 * plane + index]};
          if (consistent) {
            const ConsensusOut consensus = consensus_at(x);
            ResolveContestedPixel(cell,
                                  sums,
                                  nullptr,
                                  slot_row[x],
                                  soft_z,
                                  *rules,
                                  alpha_row + x,
                                  depth_row + x,
                                  colour_row != nullptr ? colour_row + 3 * x : nullptr,
                                  nullptr,
                                  with_consensus ? &consensus : nullptr);
          } else {
            ResolvePixel(cell,
                         sums,
                         slot_row[x],
                         soft_z,
                         alpha_row + x,
                         depth_row + x,
                         colour_row != nullptr ? colour_row + 3 * x : nullptr);
          }
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

// The pixels of `regions` to draw from one view alone: the regions where the views the vote turns
// down are several (a thin structure or a moved subject the views place a few pixels apart, each
// copy outvoted at its own place by the two views that show what is behind it: a vote keeps none
// of the copies whole), not one view far more often than the others (a glint or a subject that
// moved in one view, which the vote rightly removes). Changed pixels up to kCopiesApartPx apart
// count as one region. Such a region takes its most often heaviest view's pixels, so the
// structure is drawn once, whole, with that view's depth (BlendRules::one_view_regions).
cv::Mat SoloRegions(const cv::Mat& regions, const cv::Mat& views) {
  constexpr double kOneViewShare = 0.75;  // of a region's outvoted pixels: the vote's outlier view
  constexpr int kMinOutvotedPixels = 8;
  constexpr int kCopiesApartPx = 8;  // copies of one structure this far apart are one region
  cv::Mat grouped, labels;
  cv::dilate(
      regions, grouped, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(kCopiesApartPx + 1, kCopiesApartPx + 1)));
  const int count = cv::connectedComponents(grouped, labels, 8, CV_32S);
  labels.setTo(0, regions == 0);
  cv::Mat solo = cv::Mat::zeros(regions.size(), CV_8U);
  if (count <= 1) return solo;
  // Per region, how often each view is outvoted and how often it is the heaviest (value-initialised: zeros).
  std::vector<std::array<int, 256>> outvoted(count), heaviest(count);
  for (int y = 0; y < regions.rows; ++y) {
    const int* label = labels.ptr<int>(y);
    const uint8_t* v = views.ptr<uint8_t>(y);
    for (int x = 0; x < regions.cols; ++x) {
      if (label[x] == 0) continue;
      ++outvoted[label[x]][v[2 * x]];
      ++heaviest[label[x]][v[2 * x + 1]];
    }
  }
  std::vector<int> drawn_from(count, -1);
  for (int r = 1; r < count; ++r) {
    int total = 0, top = 0;
    for (int view = 0; view < ViewSlots::kNone; ++view) {
      total += outvoted[r][view];
      top = std::max(top, outvoted[r][view]);
    }
    if (total < kMinOutvotedPixels || top >= kOneViewShare * total) continue;
    drawn_from[r] = static_cast<int>(std::max_element(heaviest[r].begin(), heaviest[r].begin() + ViewSlots::kNone) -
                                     heaviest[r].begin());
  }
  for (int y = 0; y < regions.rows; ++y) {
    const int* label = labels.ptr<int>(y);
    const uint8_t* v = views.ptr<uint8_t>(y);
    uint8_t* row = solo.ptr<uint8_t>(y);
    for (int x = 0; x < regions.cols; ++x) row[x] = label[x] != 0 && v[2 * x + 1] == drawn_from[label[x]] ? 255 : 0;
  }
  return solo;
}

// The colour consensus where it changes a region of pixels, not a lone pixel or a line one or
// two pixels wide (which is what views a fraction of a pixel out of register leave along the
// edges of fine texture, where their blend is the better estimate): what a 5x5 opening of the
// changed pixels keeps takes the consensus's colour, alpha and depth, and its double-image mark.
// So do the double images the consensus resolves where they form a second image, not sampling
// (taking every such pixel costs the simulated scenes 0.6 dB with exact depth).
void TakeRegionalConsensus(FrameComposite* out) {
  constexpr double kMeanChangeSigmaPx = 1.5;
  constexpr double kMinMeanChangeLevels = 8;
  cv::Mat regions;
  const cv::Mat changed = out->consensus_mark != 0;
  if (cv::countNonZero(changed) == 0) return;
  cv::morphologyEx(changed, regions, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)));
  regions &= changed;
  // Double images the consensus resolves, in blocks of 3x3 or more where it moves the local mean
  // colour (sampling of fine texture differs from view to view in both directions, and the
  // differences average out; a second image does not).
  const cv::Mat resolved = (out->consensus_mark & (kBlendDouble | kConsensusDouble)) == kBlendDouble;
  cv::Mat blocks;
  cv::morphologyEx(resolved, blocks, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3)));
  if (cv::countNonZero(blocks) > 0) {
    cv::Mat change(out->colour.size(), CV_32FC3, cv::Scalar::all(0)), channels[3];
    cv::subtract(out->consensus_colour, out->colour, change, blocks);
    cv::GaussianBlur(change, change, cv::Size(0, 0), kMeanChangeSigmaPx);
    cv::split(cv::abs(change), channels);
    const cv::Mat mean_change = cv::max(channels[0], cv::max(channels[1], channels[2]));
    regions |= blocks & (mean_change > kMinMeanChangeLevels);
  }
  out->consensus_colour.copyTo(out->colour, regions);
  out->consensus_alpha.copyTo(out->alpha, regions);
  out->consensus_depth.copyTo(out->depth, regions);
  if (!out->double_image.empty()) {
    const cv::Mat consensus_double = (out->consensus_mark & kConsensusDouble) != 0;
    consensus_double.copyTo(out->double_image, regions);
  }
  if (out->consensus_views.empty()) return;
  // One-view regions: where the vote turned down several views, one view's pixels instead.
  const cv::Mat solo = SoloRegions(regions, out->consensus_views);
  out->solo_colour.copyTo(out->colour, solo);
  out->solo_alpha.copyTo(out->alpha, solo);
  out->solo_depth.copyTo(out->depth, solo);
  if (!out->double_image.empty()) out->double_image.setTo(0, solo);
}

}  // namespace

void CompositePreview(const LayeredScene& scene,
                      const std::vector<FrameView>& frame_views,
                      const std::vector<ViewSlots>& slots,
                      int width,
                      int height,
                      bool with_colour,
                      FrameComposite* out,
                      const BlendRules* rules) {
  if (rules != nullptr && rules->measure_double_images) {
    out->double_image.create(height, width, CV_8U);
  } else {
    out->double_image.release();
  }
  if (with_colour) {
    out->colour.create(height, width, CV_32FC3);
  } else {
    out->colour.release();
  }
  out->alpha.create(height, width, CV_32F);
  out->depth.create(height, width, CV_32F);
  if (with_colour && rules != nullptr && rules->consistent && rules->colour_apart_levels > rules->colour_agree_levels) {
    out->consensus_colour.create(height, width, CV_32FC3);
    out->consensus_alpha.create(height, width, CV_32F);
    out->consensus_depth.create(height, width, CV_32F);
    out->consensus_mark.create(height, width, CV_8U);
  } else {
    out->consensus_mark.release();
  }
  if (!out->consensus_mark.empty() && rules->one_view_regions) {
    out->solo_colour.create(height, width, CV_32FC3);
    out->solo_alpha.create(height, width, CV_32F);
    out->solo_depth.create(height, width, CV_32F);
    out->consensus_views.create(height, width, CV_8UC2);
  } else {
    out->consensus_views.release();
  }
  const std::vector<std::vector<BandEntry>> bands = BinSegmentsIntoBands(frame_views, height);
  const SoftZ& soft_z = scene.soft_z();
  std::atomic<long> fragments{0};
  // Witnesses are drawn only for the colour consensus's votes (OutvotedYield).
  const bool vote = !out->consensus_mark.empty();
  cv::parallel_for_(cv::Range(0, static_cast<int>(bands.size())), [&](const cv::Range& range) {
    BandBuffers& band = ThreadBandBuffers();
    band.Reserve(kBandRows * width);
    long count = 0;
    for (int b = range.start; b < range.end; ++b) {
      const int row_begin = b * kBandRows, row_end = std::min(height, row_begin + kBandRows);
      for (const SlotPass pass : {SlotPass::kBlendable, SlotPass::kWitness}) {
        // Witnesses only over the rows where one is wanted.
        int draw_begin = row_begin, draw_end = row_end;
        if (pass == SlotPass::kWitness &&
            (!vote ||
             !RowsWantingWitnesses(
                 slots, band, width, row_begin, row_end, rules->colour_agree_levels, &draw_begin, &draw_end))) {
          break;
        }
        for (const BandEntry& entry : bands[b]) {
          const FrameView& fv = frame_views[entry.frame_view];
          if (!(pass == SlotPass::kWitness ? fv.witnesses : fv.blends)) continue;
          count += CompositeSegment(scene.views()[fv.view],
                                    fv,
                                    fv.segments[entry.setup],
                                    slots,
                                    width,
                                    row_begin,
                                    draw_begin,
                                    draw_end,
                                    with_colour,
                                    rules != nullptr,
                                    pass,
                                    &band);
        }
      }
      ResolveBand(slots, soft_z, width, row_begin, row_end, with_colour, rules, &band, out);
    }
    fragments += count;
  });
  out->fragments = fragments;
  if (!out->consensus_mark.empty()) TakeRegionalConsensus(out);
}

}  // namespace px::render
