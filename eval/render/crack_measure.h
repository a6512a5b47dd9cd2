// Cracks in a rendered view, measured against the true depth of the same view: thin lines where
// a farther surface shows through a near one that has no gap there (neighbouring segments of one
// surface whose projections separate when the view is magnified, issue 5). A crack pixel renders
// far behind its true depth, while on both sides of it, across a gap of at most `max_gap_px`
// along a row, a column or a diagonal, the render is near its true depth and the true surface is
// continuous with the pixel's (so a real thin gap in the scene is not counted).
#pragma once

#include <opencv2/core.hpp>

namespace px::eval {

struct CrackMeasureOptions {
  // A pixel renders "far behind" when its depth exceeds the true depth by this fraction, and
  // "near" when it does not. (0, 10].
  double far_fraction = 0.1;
  // Widest gap counted as a crack, in pixels between the two near sides. [1, 8].
  int max_gap_px = 3;
};

struct CrackReport {
  int crack_pixels = 0;
  double crack_fraction = 0;  // of the pixels with true depth
};

// `rendered_depth_m` and `true_depth_m`: CV_32F of one size, z in metres; pixels with no true
// depth (0, or not finite) count neither as cracks nor as near sides. Returns the cracks and,
// when `cracks` is not null, a CV_8U map of them (255).
CrackReport MeasureCracks(const cv::Mat& rendered_depth_m,
                          const cv::Mat& true_depth_m,
                          const CrackMeasureOptions& options = {},
                          cv::Mat* cracks = nullptr);

}  // namespace px::eval
