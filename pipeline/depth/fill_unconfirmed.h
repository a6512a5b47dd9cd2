// Background-side filling of the pixels whose depth no other view confirms (the consistency
// check, consistency.h): in a pair these are mostly the half-occluded regions beside foreground
// objects and the border strip the other view does not see, where matching had no true partner
// and picked an arbitrary plane. Each run of them along a row takes the farther of the confirmed
// depths at its two ends: the surface that continues behind the occluder (the left-right check
// and fill of classic two-view stereo, as OpenCV's SGBM reference in the evaluation gets too).
#pragma once

#include <opencv2/core.hpp>

namespace px::depth {

// `confirmed`: CV_8U, 0 where no other view confirms the pixel. `depth_m`: CV_32F of that size,
// > 0 where known. Runs with a confirmed known depth at neither end stay as they are. Returns
// how many pixels changed.
int FillUnconfirmedFromBackground(const cv::Mat& confirmed, cv::Mat* depth_m);

}  // namespace px::depth
