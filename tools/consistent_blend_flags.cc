#include "tools/consistent_blend_flags.h"

namespace px::cli {

void AddConsistentBlendFlags(CLI::App& command, ConsistentBlendOptions* options) {
  command
      .add_option("--consistent-blend",
                  options->enabled,
                  "Draw pixels whose views contradict each other, or blend two images of one place, from the views "
                  "the more heavily weighted ones do not contradict (true, false)")
      ->capture_default_str();
  command
      .add_option("--dominance-exponent",
                  options->dominance_exponent,
                  "How fast the more heavily weighted view takes over a contested pixel, [1, 64]")
      ->capture_default_str();
  command
      .add_option("--free-space-px",
                  options->free_space_px,
                  "A view contradicts a surface it sees past by more than this many pixels of disparity, (0, 100]")
      ->capture_default_str();
  command
      .add_option("--contradiction-levels",
                  options->colour_levels,
                  "... and in a colour more than this many levels away, [1, 255]")
      ->capture_default_str();
  command
      .add_option("--agree-levels",
                  options->colour_agree_levels,
                  "Views blended at one depth whose colours differ by more than this many levels show two images: "
                  "the lighter yields, [0, 255]")
      ->capture_default_str();
  command
      .add_option("--apart-levels",
                  options->colour_apart_levels,
                  "... in full from this many levels ([0, 255]; not above --agree-levels: off)")
      ->capture_default_str();
  command
      .add_option("--one-view-regions",
                  options->one_view_regions,
                  "Where the colour consensus outvotes several views in one region, draw it from its most heavily "
                  "weighted view alone (true, false)")
      ->capture_default_str();
}

}  // namespace px::cli
