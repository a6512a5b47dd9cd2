// Depth-aware exemplar inpainting of large holes, the offline renderer's hole filling (paper 6.2;
// ALGORITHM.md section 10): Criminisi et al.'s priority order and patch copying, with patches
// searched in a window around the target, the hole's boundary depths split into a foreground and a
// background cluster, and only background lending confidence and patches, so that disocclusions
// are filled from the background side. Depth is inpainted too (reverse soft z blend).
#pragma once

#include <opencv2/core.hpp>

#include "pipeline/render/soft_z.h"

namespace px::render {

struct InpaintOptions {
  int patch_radius_px = 2;    // 5x5 patches
  int window_radius_px = 50;  // sources centred within 101x101 of the target
  int depth_radius_px = 3;    // 7x7 reverse soft z blend for a filled pixel's depth
  // false: holes touching the image's border (where the camera sees past every source's field
  // of view) are left unfilled for the caller (border_holes.h). They have known pixels on one
  // side only, and there even the reverse soft z's smear scored 3 to 6 dB better than patches
  // (eval render, turned viewpoints); the offline renderer passes false. true: every hole, as in the paper.
  bool fill_border_holes = true;
};

struct InpaintReport {
  int components = 0;            // connected holes filled
  int border_components = 0;     // left alone: touching the image border (fill_border_holes false)
  int two_layer_components = 0;  // whose boundary split into foreground and background
  int pixels = 0;                // pixels filled
  int patches = 0;               // patches copied
  int fallback_pixels = 0;       // filled by the reverse soft z blend: no background source anywhere
};

// Fills the pixels where `target` (CV_8U) is non-zero, each 8-connected part on its own. Known
// pixels are those where `known` (CV_8U) is non-zero and `target` is zero; `colour` (CV_32FC3) and
// `depth` (CV_32F) are read there and written on the targets; filled targets are marked in `known`.
InpaintReport InpaintDepthAware(const SoftZ& soft_z,
                                const InpaintOptions& options,
                                const cv::Mat& target,
                                cv::Mat* known,
                                cv::Mat* colour,
                                cv::Mat* depth);

}  // namespace px::render
