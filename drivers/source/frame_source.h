// The one interface every camera driver and simulated sensor implements. The device layer
// only ever sees FrameSource; the pipeline never sees it at all.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <string_view>

#include "pipeline/core/frame_set.h"
#include "pipeline/core/rig_calibration.h"

namespace px {

struct SourceConfig {
  PixelFormat pixel_format = PixelFormat::kBgr888;
  int width = 0;  // sensor frame (lattice) or per-image (image set) size; 0 = the source's native size
  int height = 0;
  int shots = 1;  // images per frame set for image-set sources (hand-held: 2..15); 1 for a lattice sensor

  friend bool operator==(const SourceConfig&, const SourceConfig&) = default;
};

std::string DescribeConfig(const SourceConfig& config);  // "SRGGB8 1944x1464 x1"

struct SourceDescription {
  std::string model;  // "sim:pop9", "replay:/path", "v4l2:/dev/video0"
  FrameSetKind kind = FrameSetKind::kLatticeFrame;
  std::optional<RigCalibration> rig;  // the factory calibration, when the source knows it
  // A lattice frame without a rig calibration: what is known of its lattice (a lattice photo's
  // upright tiles, the count the user gave), for finding it blind.
  std::optional<LatticeHint> lattice;
};

enum class ConfigureResult {
  kValid,     // granted == wanted
  kAdjusted,  // granted differs from wanted (e.g. nearest supported size); frames follow granted
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;

  virtual std::string_view Name() const = 0;  // "sim", "replay", "v4l2", ...
  virtual SourceDescription Describe() const = 0;

  // Grants what it can (libcamera's validate()): fills *granted and says whether it adjusted.
  // Fails (INVALID_ARGUMENT) when nothing close to `wanted` is possible.
  virtual StatusOr<ConfigureResult> Configure(const SourceConfig& wanted, SourceConfig* granted) = 0;

  // Captures one frame set. DEADLINE_EXCEEDED after `timeout`; UNAVAILABLE when the camera has
  // gone; FAILED_PRECONDITION before Configure or after Stop. Per-frame problems are reported
  // in Frame::status, not as an error, so a partly bad capture is still kept.
  virtual StatusOr<FrameSet> Next(std::chrono::milliseconds timeout) = 0;

  // Releases the camera. Idempotent. Next() fails afterwards until Configure is called again.
  virtual void Stop() = 0;
};

// Checks every frame against the granted configuration and marks bad ones in place
// (kWrongFormat for a size or format mismatch, kCorrupt for a short buffer), naming the problem
// in status_detail. Returns OK when at least one frame is usable, else the first problem.
Status CheckFrameSet(const SourceConfig& granted, FrameSet* frames);

}  // namespace px
