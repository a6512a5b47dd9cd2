// Holes: the paper's hole metric H(V) (section 4.2.1) and the preview's hole filling by the reverse
// soft z-buffer (section 6.1; ALGORITHM.md sections 6 and 9).
#pragma once

#include <opencv2/core.hpp>

#include "pipeline/render/soft_z.h"

namespace px::render {

// H(V) = sum over hole pixels of d(p)^k / (w h), d(p) the Euclidean distance to the nearest covered
// pixel: it penalises large holes (hard to inpaint) over many small ones; a viewpoint is valid when
// H < 2 with k = 3. `coverage` is CV_8U, 0 = hole. Nothing covered: every pixel counts
// hypot(w, h)^k.
double HoleScore(const cv::Mat& coverage, double exponent = 3.0);

struct HoleFillReport {
  int hole_pixels = 0;   // unknown before filling
  int first_pass = 0;    // filled by pass 1 (every hole under 2 radius + 1 px across is filled whole)
  int later_passes = 0;  // filled ring by ring inwards by the passes after it
  int passes = 0;        // passes run
  int unfilled = 0;      // left unknown (nothing known in the image, or max_passes reached)
};

// Fills unknown pixels of `colour` (CV_32FC3) and `depth` (CV_32F) where `known` (CV_8U) is 0, by
// the reverse soft z-buffer: over the known pixels of the (2 radius + 1)^2 window, the farthest
// depth gets weight 1 and nearer ones w_z(z_far - z) (eq. 1 in reverse), no spatial weight.
// Pass i fills the pixels within Chebyshev distance i * radius of the originally known ones,
// reading only pixels known before it. max_passes = 0: until every pixel is filled; 1: small holes
// and the rims of larger ones only. Filled pixels are marked 255 in `known`. `only` (CV_8U, may be
// null): fill just the unknown pixels where it is non-zero; the other unknown ones are left alone.
HoleFillReport FillHolesReverseSoftZ(const SoftZ& soft_z,
                                     int radius_px,
                                     int max_passes,
                                     cv::Mat* known,
                                     cv::Mat* colour,
                                     cv::Mat* depth,
                                     const cv::Mat* only = nullptr);

// The hole pixels (known == 0) of connected holes (8-connected) that pass 1 fills completely,
// i.e. every pixel within Chebyshev distance `radius_px` of a known pixel: CV_8U, 255 there.
cv::Mat SmallHoles(const cv::Mat& known, int radius_px);

}  // namespace px::render
