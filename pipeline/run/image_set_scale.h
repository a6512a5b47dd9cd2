// Photos from a hand-held camera are processed at a working size: a 12 MP phone photo taken at
// full size through depth and rendering costs minutes and gigabytes on a 2-core device (three
// 8 MP photos: 46 s of depth, 4.5 GB of memory, and an 8 MP clip), far from a clip in seconds.
// The clip is then drawn at the working size, the views' resolution. A palette image's dither is
// removed on the way, since it would read as texture the views disagree on.
#pragma once

#include <optional>
#include <string>

#include "pipeline/core/frame_set.h"
#include "pipeline/core/rig_calibration.h"

namespace px {

// An image set at its working size, and one line for the log saying what was scaled.
struct WorkingImageSet {
  FrameSet capture;
  RigCalibration rig;
  std::string note;
};

// `shot` with every usable frame whose longer side exceeds `max_side_px` scaled down to it
// (INTER_AREA, re-encoded as BGR888; the frame's focal length from its metadata with it, and a
// rig lens calibrated for the frame's full size too), and every dithered palette image (a GIF's
// frames; palette_dither.h) without its dither; made straight from `shot`, so no full-size copy is
// held beside it. Frames that are not OK, or cannot be decoded, are kept as they are for the
// stages after to report. nullopt when nothing needs either (max_side_px 0 and no palette images,
// a lattice frame, photos within the size): use `shot` itself.
std::optional<WorkingImageSet> ImageSetAtWorkingSize(int max_side_px, const FrameSet& shot, const RigCalibration& rig);

}  // namespace px
