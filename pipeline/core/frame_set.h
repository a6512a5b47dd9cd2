// What one press of the button captures: one multi-lens sensor frame, or several images from a
// hand-held or tethered camera. A bad image is data (status + detail), never a crash.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/pixel_format.h"

namespace px {

enum class FrameSetKind {
  kLatticeFrame,  // one sensor frame holding a lattice of sub-images
  kImageSet,      // several images, one view each (hand-held, tethered)
};

enum class FrameStatus {
  kOk,
  kCorrupt,     // the buffer is truncated or garbled
  kDropped,     // the sensor did not deliver this frame
  kWrongFormat  // size or pixel format differs from what was configured
};

std::string_view FrameSetKindName(FrameSetKind kind);  // "lattice_frame", "image_set"
StatusOr<FrameSetKind> ParseFrameSetKind(std::string_view name);
std::string_view FrameStatusName(FrameStatus status);  // "ok", "corrupt", "dropped", "wrong_format"
StatusOr<FrameStatus> ParseFrameStatus(std::string_view name);

struct Frame {
  RawImage image;
  uint64_t sequence = 0;     // the sensor's frame counter
  int64_t timestamp_ns = 0;  // capture time (CLOCK_MONOTONIC or the source's injected clock)
  FrameStatus status = FrameStatus::kOk;
  std::string status_detail;  // why status is not kOk, for logs and reports
  // The lens's focal length in this image's pixels, from the image's own metadata (a JPEG's
  // EXIF); 0 = unknown, and structure from motion then self-calibrates it.
  double focal_length_px = 0;
  std::string focal_length_source;  // how it was found ("EXIF 35 mm equivalent focal length"); "" if unknown
  // The JPEG file `image` was decoded from (an RGB888 image, upright by the file's EXIF
  // orientation), when the camera or the photo delivered one: a recording keeps it byte for byte
  // instead of re-encoding the pixels. Empty otherwise.
  std::vector<uint8_t> jpeg;
};

struct FrameSet {
  FrameSetKind kind = FrameSetKind::kLatticeFrame;
  uint64_t capture_id = 0;    // increments per press
  std::vector<Frame> frames;  // one for kLatticeFrame, one per view for kImageSet

  int NumUsableFrames() const;
};

}  // namespace px
