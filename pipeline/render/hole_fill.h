// Filling the pixels of a rendered view that no source covered (paper 6.1 "Hole filling" and 6.2).
#pragma once

#include <opencv2/core.hpp>

namespace px::render {

struct HoleFillReport {
  int hole_pixels = 0;       // pixels not covered before filling
  int filled_from_far = 0;   // small holes and hole rims, within the radius of covered pixels
  int propagated = 0;        // the rest of larger holes, filled ring by ring from their rims
};

// The paper's hole metric H(V) = sum over hole pixels of d(p)^k / (w h), d(p) the distance to
// the nearest covered pixel; it penalises large holes (hard to inpaint) over many small ones.
// The paper calls a viewpoint valid when H < 2 with k = 3. `coverage` is CV_8U, 0 = hole.
double HoleScore(const cv::Mat& coverage, double exponent = 3.0);

// Fills the holes of `bgr` (CV_8UC3) and `depth_m` (CV_32F) where `coverage` is 0. A hole pixel
// with known pixels within `radius_px` (Chebyshev) takes their mean weighted towards the farthest
// depth (the paper's "reverse soft z": a disocclusion reveals background, so the foreground must
// not bleed in) and by proximity; its depth is filled the same way. Larger holes are filled ring
// by ring inwards the same way, which carries the background across them; unlike Telea's
// inpainting (cv::inpaint) it never mixes the foreground in, and costs time in proportion to the
// hole area only.
HoleFillReport FillHoles(const cv::Mat& coverage, int radius_px, float soft_z_band, cv::Mat* bgr, cv::Mat* depth_m);

}  // namespace px::render
