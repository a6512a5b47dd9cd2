// Per-view photometric equalisation: the lenses of a film camera or a cheap lens array, and the
// shots of a hand-held set, differ in exposure, colour cast and vignetting. Each view's colours
// are brought to a reference view's by a smooth gain field per channel (exp of a quadratic in the
// image coordinates plus a fourth-power radial term: exposure, tilt and vignetting, shared by the
// channels, and a constant per channel: the colour cast), fitted
// robustly to the ratio of the two images, the reference moved onto the view along dense optical
// flow (DIS) and both heavily blurred: parallax is followed, occlusions and a moving subject
// (whose flow does not come back) are left out, and what remains is light. The shape terms are
// kept only where they explain clearly more than an exposure and a cast alone. Matching
// (zero-mean normalised correlation) is blind to gain already; the blend and the morph are not.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/core/view.h"

namespace px::calib {

struct PhotometricOptions {
  bool enabled = true;
  int working_width_px = 192;  // the fit's image width, [32, 1024]
  // Blur of the fit's images, a fraction of their width (0, 0.2]: what the flow leaves of
  // parallax and texture blurs away.
  double blur_fraction = 0.03;
  // A view whose field stays within this of 1 everywhere is left as it is (the same exposure).
  double min_change = 0.02;
  // ... or whose mean difference from the reference (grey levels over the channels, blurred,
  // aligned) is under this: parallax residue alone (synthetic views of one exposure measure
  // 0.5-3; real lenses or shots that differ in light 4-30).
  double min_difference = 4.0;
  // ... or whose difference from the reference (blurred, aligned) it lowers by less than this
  // fraction: what remains is not light. The same margin decides whether the shape terms are kept.
  double min_improvement = 0.15;
  double max_gain = 2.5;  // fields are clamped to [1 / max_gain, max_gain], (1, 10]

  Status Validate() const;
};

struct ViewPhotometry {
  ViewId view;
  bool applied = false;
  cv::Vec3d centre_gain{1, 1, 1};  // the field at the image centre (B, G, R)
  double corner_falloff = 1;       // mean over channels of corner / centre gain (vignetting difference)
  // Mean absolute difference (levels, over the channels, blurred, aligned) from the reference,
  // before and after.
  double difference_before = 0;
  double difference_after = 0;
  std::string note;  // why it was not applied, when it was not
};

struct PhotometricReport {
  ViewId reference;
  std::vector<ViewPhotometry> views;  // one per view, the reference included (never changed)
  double ms = 0;
  std::string Summary() const;  // one line for the log
};

// Equalises every view of `views` to views[reference_index] in place (images stay CV_8UC3).
// Views of any sizes; too small or blank views are left as they are, with a note.
StatusOr<PhotometricReport> EqualisePhotometry(std::vector<View>* views,
                                               int reference_index,
                                               const PhotometricOptions& options);

}  // namespace px::calib
