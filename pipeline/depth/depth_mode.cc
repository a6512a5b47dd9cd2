#include "pipeline/depth/depth_mode.h"

#include <algorithm>
#include <cstdio>
#include <limits>

#include "pipeline/core/order_statistics.h"
#include "pipeline/core/rigid3.h"

namespace px {
namespace {

// Per view: the disparity range (near end of the depth range minus far end) between it and its
// nearest neighbour by camera centre, in its own pixels; the median over views.
double MedianNeighbourDisparityPx(const std::vector<View>& views, double min_depth_m, double max_depth_m) {
  std::vector<double> disparities;
  disparities.reserve(views.size());
  for (size_t i = 0; i < views.size(); ++i) {
    const Eigen::Vector3d centre = CameraCentre(views[i].cam_from_world);
    double nearest = std::numeric_limits<double>::infinity();
    for (size_t j = 0; j < views.size(); ++j) {
      if (j != i) nearest = std::min(nearest, (CameraCentre(views[j].cam_from_world) - centre).norm());
    }
    disparities.push_back(views[i].camera.fx * nearest * (1.0 / min_depth_m - 1.0 / max_depth_m));
  }
  return Median(std::move(disparities));
}

}  // namespace

DepthModeChoice ChooseDepthMode(const std::vector<View>& views, const DepthOptions& options) {
  DepthModeChoice choice;
  choice.options = options;
  if (options.mode == DepthMode::kStandard) {
    choice.reason = "standard options (asked for)";
    return choice;
  }
  if (options.mode == DepthMode::kLightField) {
    choice.options = LightFieldDepthOptions(options);
    choice.light_field = true;
    choice.reason = "light-field options (asked for)";
    return choice;
  }
  const int num_views = static_cast<int>(views.size());
  char text[200];
  if (num_views < options.light_field_min_views || !options.HasDepthRange()) {
    std::snprintf(text,
                  sizeof(text),
                  "standard options: %d views, a light field has at least %d",
                  num_views,
                  options.light_field_min_views);
    choice.reason = text;
    return choice;
  }
  choice.neighbour_disparity_px = MedianNeighbourDisparityPx(views, options.min_depth_m, options.max_depth_m);
  choice.light_field = choice.neighbour_disparity_px <= options.light_field_max_disparity_px;
  if (choice.light_field) choice.options = LightFieldDepthOptions(options);
  std::snprintf(text,
                sizeof(text),
                "%s options: %d views, nearest neighbours %.1f px apart over %.2f to %.2f m (%s %.0f)",
                choice.light_field ? "light-field" : "standard",
                num_views,
                choice.neighbour_disparity_px,
                options.min_depth_m,
                options.max_depth_m,
                choice.light_field ? "a light field: at most" : "over",
                options.light_field_max_disparity_px);
  choice.reason = text;
  return choice;
}

}  // namespace px
