// What the depth stage tells the stages after it (and the log) about how far its depth can be
// trusted: per view, how much is confident, where it is not, whether the view agrees with the
// others at all, and warnings with reasons. The direction stage uses the low-confidence masks to
// keep the virtual camera away from regions whose depth is guesswork; the pipeline drops views
// that disagree with the rest (a lens that saw another scene) before rendering.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/core/view.h"

namespace px {

struct ViewDepthReport {
  ViewId id;
  bool computed = false;            // false for views used only as neighbours
  double confident_fraction = 0;    // pixels with confidence >= 0.5
  double consistent_fraction = 0;   // pixels whose depth another view confirms (consistency check)
  double textureless_fraction = 0;  // pixels whose matching window has no texture
  double saturated_fraction = 0;    // pixels at 0 or 255 in some channel... at >= 250 in all channels
  double dark_fraction = 0;         // pixels darker than 8 grey levels
  // Median over textured pixels of the best matching cost against the neighbours before
  // aggregation, in [0, 2] (1 - ZNCC, best half of the neighbours): under 0.1 for views of the
  // same scene, 0.3 and more for unrelated images (the best of many depths matches by chance).
  double median_match_cost = 0;
  // The median over the same pixels of their cost at depths not their own (the mean over planes):
  // a view of the scene matches well below it; a view of another scene hardly below.
  double median_typical_cost = 0;
  bool disagrees = false;  // matches none of its neighbours: left out as a neighbour
  cv::Mat low_confidence;  // CV_8U at view resolution: 255 where depth is unreliable
  int num_segments = 0;
  int num_boundary_pixels = 0;       // pixels shared by two segment layers (soft depth edges)
  std::vector<std::string> reasons;  // why this view's depth is degraded, if it is
};

struct DepthReport {
  std::vector<ViewDepthReport> views;  // in the views' order
  std::vector<ViewId> disagreeing_views;
  double confident_fraction = 0;  // over all computed views
  // Pixels whose depth another view confirms, over the computed views that match their neighbours
  // (0 when none does): unlike confidence, it hardly depends on the working resolution.
  double consistent_fraction = 0;
  std::vector<std::string> warnings;  // one line each, for the log and the clip's JSON
  bool light_field = false;           // ran with the light-field options (depth_mode.h)
  std::string mode;                   // which options, and why
  double matching_ms = 0;             // time per part of the stage, all views
  double consistency_ms = 0;
  double segments_ms = 0;
  double layers_ms = 0;
};

}  // namespace px
