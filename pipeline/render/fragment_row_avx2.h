// The preview compositor's inner loop (preview_compositor.cc, CompositeSegment) eight fragments at
// a time with AVX2, for CPUs that have it: one row of one segment's rectangle into its view's
// slot of the band's rendering buffers. The same operations in the same order lane by lane as the
// one-fragment loop (no FMA, which would round differently), so the output is the same bit for
// bit; render/render_test (FragmentRowAvx2MatchesTheScalarPath) compares the two. The file is
// built for baseline x86-64: only the kernel's own functions carry the AVX2 target, and callers
// ask CpuHasAvx2() first.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "pipeline/render/layered_scene.h"
#include "pipeline/render/view_mesh.h"

namespace px::render {

// Everything the row needs: the segment's texels and terms, the row's slots and band cells.
struct FragmentRow {
  // The view's padded texels (SceneView::TexelPtr(-1, -1)) and row stride in texels.
  const SegmentTexel* texels = nullptr;
  int texel_stride = 0;
  int32_t segment = 0;                 // the segment sampled
  uint8_t view = 0;                    // the mesh's view index, looked for in the pixel's slots
  std::array<float, 4> rect{};         // the segment's rectangle, source pixels (SceneSegment::rect)
  // Homogeneous source coordinates (h0 x + hx0, h3 x + hy0, h6 x + hw0) and inverse depth
  // (iz_x x + iz0) along the row (SegmentRow, compositor.h).
  float h0 = 0, h3 = 0, h6 = 0, hx0 = 0, hy0 = 0, hw0 = 0, iz_x = 0, iz0 = 0;
  int x_begin = 0, x_end = 0;          // pixels [x_begin, x_end) of the row
  const ViewSlots* slot_row = nullptr; // the row's viewing weights, indexed by x
  // The band's cells (4 floats a pixel) and depth sums: slot k of pixel x of this row is
  // cells[4 (k plane + row_offset + x)] and depths[k plane + row_offset + x].
  float* cells = nullptr;
  float* depths = nullptr;
  int plane = 0, row_offset = 0;
  bool with_colour = true;
};

// True when the CPU runs AVX2 (checked once).
bool CpuHasAvx2();

// Composites the row (see CompositeSegment) and returns the fragments generated. Call only when
// CpuHasAvx2().
long CompositeFragmentRowAvx2(const FragmentRow& row);

}  // namespace px::render
