// Photos from a hand-held camera are processed at a working size: a 12 MP phone photo taken at
// full size through depth and rendering costs minutes and gigabytes on a 2-core device (three
// 8 MP photos: 46 s of depth, 4.5 GB of memory, and an 8 MP clip), far from a clip in seconds.
// The clip is then drawn at the working size, the views' resolution.
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/frame_set.h"
#include "pipeline/core/rig_calibration.h"

namespace px {

// Scales every usable frame of an image set whose longer side exceeds `max_side_px` down to it
// (INTER_AREA; the frame's focal length from its metadata with it, and a rig lens calibrated for
// the frame's full size too), re-encoded as BGR888. Frames that are not OK, or cannot be decoded,
// are left as they are for the stages after to report. Returns one line for the log ("" when
// nothing was scaled). max_side_px 0, or a lattice frame: nothing changes.
std::string ScaleImageSetToWorkingSize(int max_side_px, FrameSet* capture, RigCalibration* rig);

}  // namespace px
