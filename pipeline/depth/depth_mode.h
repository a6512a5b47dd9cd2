// Which set of depth options suits a shot: the product's (lattices, hand-held sets, stereo pairs:
// neighbours several to tens of pixels apart) or LightFieldDepthOptions' (a dense grid of views a
// pixel or two apart: a plenoptic camera's sub-aperture views). Chosen from the views' poses
// and the depth range alone, before any matching, so the stage runs once.
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/view.h"
#include "pipeline/depth/depth_options.h"

namespace px {

struct DepthModeChoice {
  DepthOptions options;  // what the stage runs with
  bool light_field = false;
  // The largest disparity between a view and its nearest neighbour, at view resolution, at the
  // near end of the depth range (the median over views), px; 0 when not measured.
  double neighbour_disparity_px = 0;
  std::string reason;  // one line for the log and the report
};

// The options `options.mode` asks for; for DepthMode::kAuto, the light-field options when the
// shot has at least options.light_field_min_views views whose nearest neighbours lie at most
// options.light_field_max_disparity_px apart at the near end of the depth range. `options` must
// have a depth range (WithDefaultDepthRange).
DepthModeChoice ChooseDepthMode(const std::vector<View>& views, const DepthOptions& options);

}  // namespace px
