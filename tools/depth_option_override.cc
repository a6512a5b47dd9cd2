#include "tools/depth_option_override.h"

#include <cstdlib>
#include <utility>

namespace px::cli {

Status ApplyDepthOptionOverride(const std::string& text, DepthOptions* options) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos) return InvalidArgumentError("--option '" + text + "' is not name=value");
  const std::string name = text.substr(0, eq), value = text.substr(eq + 1);
  char* end = nullptr;
  const double number = std::strtod(value.c_str(), &end);
  if (end == value.c_str() || *end != '\0')
    return InvalidArgumentError("--option " + name + ": '" + value + "' is not a number");
  MatchingOptions& m = options->matching;
  const std::pair<const char*, double*> doubles[] = {
      {"working_scale", &options->working_scale},
      {"free_space_max_confidence", &options->free_space_max_confidence},
      {"light_field_max_disparity_px", &options->light_field_max_disparity_px},
      {"matching.plane_step_px", &m.plane_step_px},
      {"matching.cost_filter_eps", &m.cost_filter_eps},
      {"matching.min_texture_stddev", &m.min_texture_stddev},
      {"matching.sgm_step_penalty", &m.sgm_step_penalty},
      {"matching.sgm_jump_penalty", &m.sgm_jump_penalty},
      {"segments.compactness", &options->segments.compactness},
      {"segments.inlier_px", &options->segments.inlier_px},
      {"segments.coplanar_keep_fraction", &options->segments.coplanar_keep_fraction},
      {"segments.coplanar_tolerance_px", &options->segments.coplanar_tolerance_px},
      {"segments.min_support", &options->segments.min_support},
      {"segments.propagation_cost_margin", &options->segments.propagation_cost_margin},
      {"segments.weak_region_colour_lab", &options->segments.weak_region_colour_lab},
      {"segments.weak_region_cost_margin", &options->segments.weak_region_cost_margin},
      {"segments.edge_disparity_px", &options->segments.edge_disparity_px},
      {"segments.edge_label_smoothness", &options->segments.edge_label_smoothness},
      {"segments.group_depth_search_px", &options->segments.group_depth_search_px},
      {"segments.pixel_depth_tolerance_px", &options->segments.pixel_depth_tolerance_px},
      {"segments.pixel_depth_min_confidence", &options->segments.pixel_depth_min_confidence},
      {"segments.refine_offset_px", &options->segments.refine_offset_px},
      {"segments.refine_slope_px", &options->segments.refine_slope_px},
      {"segments.slanted_min_slope_px", &options->segments.slanted_min_slope_px},
      {"segments.slanted_max_change_px", &options->segments.slanted_max_change_px}};
  const std::pair<const char*, int*> ints[] = {
      {"matching.num_planes", &m.num_planes},
      {"matching.max_planes", &m.max_planes},
      {"matching.num_neighbors", &m.num_neighbors},
      {"matching.window_radius_px", &m.window_radius_px},
      {"matching.cost_filter_radius_px", &m.cost_filter_radius_px},
      {"matching.sgm_paths", &m.sgm_paths},
      {"matching.spread_neighbors", &m.spread_neighbors},
      {"segments.region_size_px", &options->segments.region_size_px},
      {"segments.refine_iterations", &options->segments.refine_iterations},
      {"segments.refine_random_trials", &options->segments.refine_random_trials},
      {"segments.slanted_ring_px", &options->segments.slanted_ring_px},
      {"segments.band_radius_px", &options->segments.band_radius_px},
      {"segments.edge_label_radius_px", &options->segments.edge_label_radius_px},
      {"min_working_width_px", &options->min_working_width_px},
      {"light_field_min_views", &options->light_field_min_views}};
  const std::pair<const char*, bool*> bools[] = {
      {"fill_unconfirmed", &options->fill_unconfirmed},
      {"free_space_replane", &options->free_space_replane},
      {"segments.edge_label_visibility", &options->segments.edge_label_visibility}};
  for (const auto& [field, target] : bools) {
    if (name != field) continue;
    if (number != 0 && number != 1) return InvalidArgumentError("--option " + name + ": '" + value + "' is not 0 or 1");
    *target = number != 0;
    return OkStatus();
  }
  for (const auto& [field, target] : doubles) {
    if (name == field) {
      *target = number;
      return OkStatus();
    }
  }
  for (const auto& [field, target] : ints) {
    if (name == field) {
      *target = static_cast<int>(number);
      return OkStatus();
    }
  }
  return InvalidArgumentError("--option: no depth option named '" + name + "'");
}

}  // namespace px::cli
