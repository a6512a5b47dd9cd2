// Palette dither: an animated GIF (and any image saved with a palette) holds at most 256 colours,
// so a photo saved that way is dithered: its colours alternate at the pixel scale (a wigglegram
// GIF of a city: a checkerboard of purple and olive over grey roofs). Matching reads that pattern
// as texture the views disagree on at every pixel, and rendering moves it across the clip as a
// shimmer, so it is removed before anything reads the frame.
#pragma once

#include <opencv2/core.hpp>

#include "pipeline/core/pixel_format.h"

namespace px {

// Most colours a palette image holds (GIF, PNG-8).
inline constexpr int kMaxPaletteColours = 256;

// Distinct colours of a 3-byte-per-pixel image (RGB888, BGR888), counted up to `limit` + 1 (so a
// photo stops the count early); other formats (a sensor's YUV or Bayer) count as `limit` + 1.
int CountColoursUpTo(const RawImage& image, int limit);

// How strongly an image alternates at the pixel scale: the median over pixels of the mean
// absolute difference, over the three channels, between the image and its 5x5 binomial blur, in
// levels. A dithered palette photo measures well above 5 (a wigglegram GIF of a city: up to 19);
// a photo, or a palette image quantised without dither, under 3. `without_dither` (may be null)
// receives the blur it was measured against, RemoveDither(bgr).
double PixelScaleResidual(const cv::Mat& bgr, cv::Mat* without_dither = nullptr);

// The residual above which a palette image counts as dithered.
inline constexpr double kDitherResidualLevels = 5.0;

// `bgr` without its dither: a 5x5 binomial blur (separable [1 4 6 4 1] / 16), which removes
// the checkerboard at the pixel scale entirely and a 4x4 ordered dither's pattern to a quarter,
// and keeps the scale of the frame's own detail (sigma 1 px).
cv::Mat RemoveDither(const cv::Mat& bgr);

}  // namespace px
