#include "pipeline/render/fragment_row_avx2.h"

#include <immintrin.h>

#include <algorithm>

namespace px::render {
namespace {

// Only these functions use AVX2; the rest of the binary stays baseline x86-64.
#define PX_AVX2 __attribute__((target("avx2")))

// Byte offsets of a texel's fields (SegmentTexel), gathered with a scale of 8 bytes: a texel is 3
// such units, so texel indices up to 700 million fit the 32-bit gather index.
constexpr int kSegmentBytes[2] = {0, 4};
constexpr int kWeightBytes[2] = {8, 12};
constexpr int kColourBytes[2] = {16, 20};
static_assert(sizeof(SegmentTexel) == 24 && offsetof(SegmentTexel, weight) == 8 &&
                  offsetof(SegmentTexel, colour) == 16,
              "texel layout the gathers read");
static_assert(sizeof(ViewSlots) == 16 && offsetof(ViewSlots, view) == 0, "the slots' view bytes are one word");

PX_AVX2 inline __m256i GatherTexelWord(const SegmentTexel* texels, int byte_offset, __m256i index_x3, __m256i mask) {
  const int* base = reinterpret_cast<const int*>(reinterpret_cast<const char*>(texels) + byte_offset);
  return _mm256_mask_i32gather_epi32(_mm256_setzero_si256(), base, index_x3, mask, 8);
}

PX_AVX2 inline __m256 GatherTexelFloat(const SegmentTexel* texels, int byte_offset, __m256i index_x3, __m256i mask) {
  const float* base = reinterpret_cast<const float*>(reinterpret_cast<const char*>(texels) + byte_offset);
  return _mm256_mask_i32gather_ps(_mm256_setzero_ps(), base, index_x3, _mm256_castsi256_ps(mask), 8);
}

PX_AVX2 inline __m256 ColourByte(__m256i bgr1, int shift) {
  return _mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(bgr1, shift), _mm256_set1_epi32(0xFF)));
}

// sum += bgr1 * (beta * weight) lane by lane where `mask`, as SampleSegmentPremultiplied adds a
// matching texel layer (lanes not taking part add an exact +0).
struct Sample {
  __m256 b, g, r, a;
};
PX_AVX2 inline void AddTexelLayer(const SegmentTexel* texels, int layer, __m256i index_x3, __m256i mask, __m256 beta,
                                  Sample* sum) {
  const __m256 weight = GatherTexelFloat(texels, kWeightBytes[layer], index_x3, mask);
  const __m256i bgr1 = GatherTexelWord(texels, kColourBytes[layer], index_x3, mask);
  const __m256 bilinear = _mm256_mul_ps(beta, weight);
  const __m256 in = _mm256_castsi256_ps(mask);
  sum->b = _mm256_add_ps(sum->b, _mm256_and_ps(in, _mm256_mul_ps(ColourByte(bgr1, 0), bilinear)));
  sum->g = _mm256_add_ps(sum->g, _mm256_and_ps(in, _mm256_mul_ps(ColourByte(bgr1, 8), bilinear)));
  sum->r = _mm256_add_ps(sum->r, _mm256_and_ps(in, _mm256_mul_ps(ColourByte(bgr1, 16), bilinear)));
  sum->a = _mm256_add_ps(sum->a, _mm256_and_ps(in, _mm256_mul_ps(ColourByte(bgr1, 24), bilinear)));
}

PX_AVX2 inline __m256i And(__m256i a, __m256i b) { return _mm256_and_si256(a, b); }
PX_AVX2 inline __m256i AndNot(__m256i not_this, __m256i b) { return _mm256_andnot_si256(not_this, b); }
PX_AVX2 inline __m256i Greater(__m256 a, __m256 b) { return _mm256_castps_si256(_mm256_cmp_ps(a, b, _CMP_GT_OQ)); }
PX_AVX2 inline __m256i GreaterOrEqual(__m256 a, __m256 b) {
  return _mm256_castps_si256(_mm256_cmp_ps(a, b, _CMP_GE_OQ));
}
PX_AVX2 inline __m256i LessOrEqual(__m256 a, __m256 b) {
  return _mm256_castps_si256(_mm256_cmp_ps(a, b, _CMP_LE_OQ));
}
PX_AVX2 inline int Lanes(__m256i mask) { return _mm256_movemask_ps(_mm256_castsi256_ps(mask)); }

}  // namespace

bool CpuHasAvx2() {
  static const bool has_avx2 = __builtin_cpu_supports("avx2");
  return has_avx2;
}

// Lane i is pixel x0 + i. Each step mirrors CompositeSegment's loop body; a lane that `continue`s
// there leaves `active`.
PX_AVX2 long CompositeFragmentRowAvx2(const FragmentRow& row) {
  const __m256i lane_index = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i byte = _mm256_set1_epi32(0xFF), view = _mm256_set1_epi32(row.view);
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
  const __m256 weight_scale = _mm256_set1_ps(1.0f / SegmentTexel::kWeightScale);
  const __m256 rect_u_min = _mm256_set1_ps(row.rect[0]), rect_v_min = _mm256_set1_ps(row.rect[1]);
  const __m256 rect_u_max = _mm256_set1_ps(row.rect[2]), rect_v_max = _mm256_set1_ps(row.rect[3]);
  const __m256i segment = _mm256_set1_epi32(row.segment);
  // Texel offsets of the bilinear footprint (t00, t00 + 1, t01, t01 + 1) in 8-byte units.
  const int footprint_x3[4] = {0, 3, 3 * row.texel_stride, 3 * row.texel_stride + 3};
  long fragments = 0;
  alignas(32) int cell_index[8];
  alignas(32) float deltas[32], depth_deltas[8];
  for (int x0 = row.x_begin; x0 < row.x_end; x0 += 8) {
    const __m256i x = _mm256_add_epi32(_mm256_set1_epi32(x0), lane_index);
    const __m256i in_row = _mm256_cmpgt_epi32(_mm256_set1_epi32(row.x_end), x);
    // SlotOf: the slot holding the view (a view is in at most one), or none.
    const __m256i words = _mm256_mask_i32gather_epi32(
        _mm256_setzero_si256(), reinterpret_cast<const int*>(row.slot_row + x0), _mm256_slli_epi32(lane_index, 2),
        in_row, 4);
    const __m256i in0 = _mm256_cmpeq_epi32(And(words, byte), view);
    const __m256i in1 = _mm256_cmpeq_epi32(And(_mm256_srli_epi32(words, 8), byte), view);
    const __m256i in2 = _mm256_cmpeq_epi32(And(_mm256_srli_epi32(words, 16), byte), view);
    const __m256i slot = _mm256_blendv_epi8(_mm256_blendv_epi8(_mm256_set1_epi32(2), _mm256_set1_epi32(1), in1),
                                            _mm256_setzero_si256(), in0);
    __m256i active = And(in_row, _mm256_or_si256(in0, _mm256_or_si256(in1, in2)));
    if (Lanes(active) == 0) continue;
    const __m256i cell = _mm256_add_epi32(_mm256_mullo_epi32(slot, _mm256_set1_epi32(row.plane)),
                                          _mm256_add_epi32(_mm256_set1_epi32(row.row_offset), x));
    // Saturated cells take nothing more.
    const __m256 cell_alpha = _mm256_mask_i32gather_ps(zero, row.cells + 3, _mm256_slli_epi32(cell, 2),
                                                       _mm256_castsi256_ps(active), 4);
    active = AndNot(GreaterOrEqual(cell_alpha, one), active);
    // FragmentSource.
    const __m256 fx = _mm256_cvtepi32_ps(x);
    const __m256 hw = _mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(row.h6), fx), _mm256_set1_ps(row.hw0));
    active = And(active, Greater(hw, zero));
    const __m256 inv_w = _mm256_div_ps(one, hw);
    __m256 u = _mm256_mul_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(row.h0), fx), _mm256_set1_ps(row.hx0)), inv_w);
    __m256 v = _mm256_mul_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(row.h3), fx), _mm256_set1_ps(row.hy0)), inv_w);
    active = And(active, And(And(GreaterOrEqual(u, rect_u_min), LessOrEqual(u, rect_u_max)),
                             And(GreaterOrEqual(v, rect_v_min), LessOrEqual(v, rect_v_max))));
    if (Lanes(active) == 0) continue;
    // SampleSegmentPremultiplied; lanes left out sample at (0, 0) with nothing gathered.
    u = _mm256_and_ps(u, _mm256_castsi256_ps(active));
    v = _mm256_and_ps(v, _mm256_castsi256_ps(active));
    const __m256i minus_one = _mm256_set1_epi32(-1);
    const __m256i iu = _mm256_add_epi32(_mm256_cvttps_epi32(_mm256_add_ps(u, one)), minus_one);
    const __m256i iv = _mm256_add_epi32(_mm256_cvttps_epi32(_mm256_add_ps(v, one)), minus_one);
    const __m256 fu = _mm256_sub_ps(u, _mm256_cvtepi32_ps(iu)), fv = _mm256_sub_ps(v, _mm256_cvtepi32_ps(iv));
    const __m256 gu = _mm256_mul_ps(_mm256_sub_ps(one, fu), weight_scale), hu = _mm256_mul_ps(fu, weight_scale);
    const __m256 one_minus_fv = _mm256_sub_ps(one, fv);
    const __m256 beta[4] = {_mm256_mul_ps(gu, one_minus_fv), _mm256_mul_ps(hu, one_minus_fv), _mm256_mul_ps(gu, fv),
                            _mm256_mul_ps(hu, fv)};
    // TexelPtr(iu, iv) = texels + (iv + 1) stride + (iu + 1), times 3 for the 8-byte gather scale.
    const __m256i t00 = _mm256_add_epi32(_mm256_mullo_epi32(_mm256_sub_epi32(iv, minus_one),
                                                            _mm256_set1_epi32(row.texel_stride)),
                                         _mm256_sub_epi32(iu, minus_one));
    const __m256i t00_x3 = _mm256_add_epi32(t00, _mm256_add_epi32(t00, t00));
    Sample sum{zero, zero, zero, zero};
    for (int i = 0; i < 4; ++i) {
      const __m256i index_x3 = _mm256_add_epi32(t00_x3, _mm256_set1_epi32(footprint_x3[i]));
      for (int layer = 0; layer < 2; ++layer) {
        const __m256i match =
            And(active, _mm256_cmpeq_epi32(GatherTexelWord(row.texels, kSegmentBytes[layer], index_x3, active), segment));
        if (Lanes(match) != 0) AddTexelLayer(row.texels, layer, index_x3, match, beta[i], &sum);
      }
    }
    const __m256 alpha = sum.a;
    active = AndNot(LessOrEqual(alpha, _mm256_set1_ps(1e-6f)), active);
    const __m256 inv_z = _mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(row.iz_x), fx), _mm256_set1_ps(row.iz0));
    active = And(active, Greater(inv_z, zero));
    fragments += __builtin_popcount(Lanes(active));
    const __m256 z = _mm256_div_ps(one, inv_z);
    // Front to back, saturating: the fragment adds f = min(alpha, 1 - A), its colour scaled by
    // f / alpha (exactly 1 when f == alpha, where the scalar path adds the sample as it is).
    const __m256 f = _mm256_min_ps(_mm256_sub_ps(one, cell_alpha), alpha);
    active = AndNot(LessOrEqual(f, zero), active);
    int lanes = Lanes(active);
    if (lanes == 0) continue;
    _mm256_store_si256(reinterpret_cast<__m256i*>(cell_index), cell);
    _mm256_store_ps(depth_deltas, _mm256_mul_ps(f, z));
    if (row.with_colour) {
      const __m256 scale = _mm256_div_ps(f, alpha);
      const __m256 b = _mm256_mul_ps(sum.b, scale), g = _mm256_mul_ps(sum.g, scale), r = _mm256_mul_ps(sum.r, scale);
      // (b, g, r, f) per lane: lane i at deltas[8 (i % 4) + 4 (i / 4)].
      const __m256 bg_low = _mm256_unpacklo_ps(b, g), bg_high = _mm256_unpackhi_ps(b, g);
      const __m256 rf_low = _mm256_unpacklo_ps(r, f), rf_high = _mm256_unpackhi_ps(r, f);
      _mm256_store_ps(deltas, _mm256_shuffle_ps(bg_low, rf_low, 0x44));
      _mm256_store_ps(deltas + 8, _mm256_shuffle_ps(bg_low, rf_low, 0xEE));
      _mm256_store_ps(deltas + 16, _mm256_shuffle_ps(bg_high, rf_high, 0x44));
      _mm256_store_ps(deltas + 24, _mm256_shuffle_ps(bg_high, rf_high, 0xEE));
    } else {
      _mm256_store_ps(deltas, f);
    }
    for (; lanes != 0; lanes &= lanes - 1) {
      const int i = __builtin_ctz(lanes);
      float* cell_i = row.cells + 4 * static_cast<ptrdiff_t>(cell_index[i]);
      if (row.with_colour) {
        const float* delta = deltas + 8 * (i & 3) + 4 * (i >> 2);
        _mm_storeu_ps(cell_i, _mm_add_ps(_mm_loadu_ps(cell_i), _mm_load_ps(delta)));
      } else {
        cell_i[3] += deltas[i];
      }
      row.depths[cell_index[i]] += depth_deltas[i];
    }
  }
  return fragments;
}

}  // namespace px::render
