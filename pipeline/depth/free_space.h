// Free-space checks between the views' depth: a surface one view places in front of what the
// other views see through that very spot cannot be there, or they would not see past it. Weakly
// supported segments (a textureless panel that matched an occluder the other views have in front
// of it, a fronto-parallel guess from a few stray pixels) are the ones caught this way; they
// float in front of the scene and tear away from it as soon as the camera moves. Such a segment
// takes the plane of an adjacent segment that the other views confirm best, in depth and in
// colour, instead (the
// visibility constraint of multi-view depth fusion, e.g. Merrell et al. 2007, applied to the
// segments' planes rather than to pixels).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/view.h"
#include "pipeline/depth/two_layer.h"

namespace px::depth {

struct FreeSpaceOptions {
  // A point counts as seen through when another view sees a surface farther along its line of
  // sight by more than this much disparity (pixels, against that view's baseline). > 0.
  double see_through_px = 2.0;
  // ... and as confirmed when that view's depth there lies within this much disparity. > 0.
  double confirm_px = 1.0;
  // Only segments whose confidence is below this are re-planed: a well-supported plane is kept
  // even where the other views' (weaker) depth disagrees with it. [0, 1].
  double max_confidence = 0.25;
  // A segment is contradicted where most of the views it projects into see through at least
  // this fraction of its pixels. (0, 1].
  double min_seen_through_fraction = 0.5;
};

struct FreeSpaceStats {
  int contradicted = 0;  // weak segments most views see through
  int replaned = 0;      // of those, given an adjacent segment's plane
};

// Checks the segments of views[reference] (`segments`: its labels at view resolution and planes
// in its pixels) against the depth maps of `others` (indices into views; depth_m[k] CV_32F at
// views[k]'s size, empty to skip) and gives each contradicted segment the plane of an adjacent,
// uncontradicted segment that the others confirm best (adjacent ones re-planed first in turn):
// same depth and same colour (views[k].image) on more of its pixels than another colour or
// seen through. A contradicted segment no candidate is confirmed for keeps its plane: a subject that
// moved between the shots is seen through by the others too, but matches nothing in colour.
FreeSpaceStats ReplaneSeenThroughSegments(const std::vector<View>& views,
                                          const std::vector<cv::Mat>& depth_m,
                                          int reference,
                                          const std::vector<int>& others,
                                          const FreeSpaceOptions& options,
                                          SegmentImage* segments);

}  // namespace px::depth
