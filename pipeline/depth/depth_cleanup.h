// Light, edge-aware cleanup of a plane-sweep depth map: speckles lose confidence, unreliable
// pixels take their depth from confident neighbours of similar colour, and the working-scale
// result is upsampled to full resolution along image edges.
#pragma once

#include <opencv2/core.hpp>

namespace px::depth {

// Finds connected regions of at most max_size_px pixels whose plane position differs from
// their surroundings by more than max_jump_planes (cv::filterSpeckles on the plane map), and
// caps their confidence at confidence_cap. Depth is left as it is.
void LowerSpeckleConfidence(
    const cv::Mat& plane, int max_size_px, float max_jump_planes, float confidence_cap, cv::Mat* confidence);

// Replaces the inverse depth of pixels with confidence below fill_confidence by a
// confidence-weighted, edge-aware average of the whole map (fast global smoother guided by
// `guide_bgr`, normalised by the smoothed confidence); pixels in between blend linearly. Confident
// pixels keep their value. The result stays within [min_value, max_value].
void FillLowConfidence(const cv::Mat& guide_bgr,
                       const cv::Mat& confidence,
                       float fill_confidence,
                       float min_value,
                       float max_value,
                       cv::Mat* inverse_depth);

// Joint bilateral upsampling: each full-resolution pixel averages the 3x3 nearest low-resolution
// samples, weighted by distance, by colour similarity between its own full-resolution colour and
// the sample's low-resolution colour (so values do not bleed across image edges), and, for the
// value, by the sample's confidence. Outputs are CV_32F at high_guide's size.
void UpsampleJointBilateral(const cv::Mat& low_value,
                            const cv::Mat& low_confidence,
                            const cv::Mat& low_guide_bgr,
                            const cv::Mat& high_guide_bgr,
                            cv::Mat* high_value,
                            cv::Mat* high_confidence);

}  // namespace px::depth
