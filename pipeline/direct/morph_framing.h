// Framing of a two-view morph (paper 4.5) with the framing rules of the 3D moves: a morph with
// subjects is a one-subject move, not a morph "regardless of scene content". The frame shows the
// whole morph at the start and pushes in as the views morph, towards the subjects as the flow
// carries them, ending with their lower half centred (paper 4.2.3) at up to
// DirectOptions::zoom_in, every subject wholly inside every frame with the framing margin.
//
// The path says it all, so a written shot replays the same frames: the zoom at t is
// FocalAt(t) / keyframes[0].focal_px (the first key shows the whole morph), and the window
// follows path.subjects' boxes (in source_views[0]'s pixels) along the morph's flow.
#pragma once

#include <opencv2/core.hpp>

#include "pipeline/direct/camera_path.h"
#include "pipeline/direct/direct_options.h"
#include "pipeline/direct/view_morph.h"

namespace px::direct {

// Where the subjects' boxes (all of path.subjects in the morph's first view) are at time t: their
// union moved by the median flow inside it. Empty without subjects.
cv::Rect2d MorphSubjectsBoxAt(const CameraPath& path, const ViewMorph& morph, double t);

// The rectangle of the morph's image (its pixels) that frame t shows: the output's aspect, the
// widest such crop divided by the zoom at t, centred where it frames the subjects with
// `margin_fraction` of its width to spare (the image's centre if it already does) and moved from
// there towards the subjects' lower-half centre in proportion to the zoom reached, kept inside
// the image. `margin_fraction`: DirectOptions::framing_margin.
cv::Rect2d MorphWindowAt(const CameraPath& path, const ViewMorph& morph, double t, double margin_fraction);

// Sets the end zoom of a morph path (kind kMorph, two keyframes, of the morph's own size) so that
// it pushes in on its subjects: options.zoom_in, narrowed until every subject stays wholly inside
// every frame with options.framing_margin. Returns the zoom reached (1: no subjects, or no room to
// push in); a path without subjects is left with zoom 1.
double PlanMorphPushIn(const ViewMorph& morph, const DirectOptions& options, CameraPath* path);

// The frame of `path` at t cut from the morph image `image` (morph.FrameAt(t)) at output size.
cv::Mat CutMorphFrame(
    const cv::Mat& image, const CameraPath& path, const ViewMorph& morph, double t, double margin_fraction);

}  // namespace px::direct
