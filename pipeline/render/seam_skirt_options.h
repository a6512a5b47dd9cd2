// Options of the seam skirts (seam_skirts.h), apart so that render_options.h needs no more.
#pragma once

namespace px {

struct SeamSkirtOptions {
  // Two touching segments are one surface when their planes' inverse depths at a seam texel differ
  // by less than this fraction (relative); 0 = no skirts. [0, 1). Depth edges differ by far more:
  // the depth stage bands touching segments more than 1 px of disparity apart (8.5 % at 1.2 m on
  // the Pop9).
  double max_step = 0.05;
  // Nor where they differ by less than this fraction: their projections in any view the product
  // plans then stay within a small fraction of a pixel of each other, and a skirt there would only
  // add fragments and the overlap's bias. [0, max_step). Exact planes of one surface fitted in
  // blocks (sim truth, the benchmarks' analytic scenes) differ by float rounding, far below.
  // Where a seam parts by d output pixels, d ~ f' b delta / z' (f' the output focal length, b the
  // camera's move across the ray, z' the depth in the output view, delta the relative step); the
  // product's close-up ends (1.5 f, 0.7 m forward on a face 1.2 m away) reach about 430 delta at
  // 20 deg off axis, so 1e-4 is at most 0.05 px there.
  double min_step = 1e-4;
  // Layer-1 weight of a skirt texel, (0, 1]. 1 closes a seam fully however its sides part (up to
  // a source texel), but where they do not part the overlap biases the bilinear blend across the
  // seam (the first segment drawn covers part of the pixel, the second adds its full sample over
  // the rest): up to a quarter of the colour step between two texels. About a half closes the
  // cracks of the product's close-ups as well (`parallax eval render --group closeup`: 0.25 % of
  // pixels cracked against 0.24 % with 1 and 1.09 % without) at a third of that bias's cost on the
  // standard viewpoints (pipeline/render/README.md). 128/255 is exact in the GL back end's 8-bit
  // weights and the CPU's 16-bit ones (0.5 is not, and the two then part by up to 40 levels at a
  // pixel where the blend's order matters).
  float weight = 128.0f / 255;
};

}  // namespace px
