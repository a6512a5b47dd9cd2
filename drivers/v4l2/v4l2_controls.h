// Exposure and gain through V4L2 controls (VIDIOC_QUERYCTRL, VIDIOC_S_CTRL, VIDIOC_G_CTRL).
// A device may have none of them: an absent control is reported, never an error.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace px::v4l2 {

struct ControlSettings {
  std::optional<int> exposure;        // V4L2_CID_EXPOSURE_ABSOLUTE, in 100 us units; switches to manual exposure
  std::optional<int> gain;            // V4L2_CID_GAIN, device units
  std::optional<bool> auto_exposure;  // V4L2_CID_EXPOSURE_AUTO: true = auto (or aperture priority), false = manual

  bool empty() const { return !exposure && !gain && !auto_exposure; }
};

// One control as the device describes it, after any change was applied.
struct ControlState {
  uint32_t id = 0;
  std::string name;      // our name: "exposure", "gain", "auto_exposure"
  bool present = false;  // false: the device has no such control (or it is disabled)
  bool read_only = false;
  int32_t minimum = 0, maximum = 0, step = 0, default_value = 0;
  int32_t value = 0;  // read back with G_CTRL
  std::string note;   // "set to 300", "absent: exposure 300 not applied", "inactive"

  std::string ToString() const;  // "exposure=300 [1, 5000] (set to 300)", "gain: absent"
};

// Reads exposure, gain and auto exposure (in that order of names: auto_exposure, exposure, gain).
StatusOr<std::vector<ControlState>> ReadControls(int fd, const std::string& device);

// Applies the settings and returns the controls read back. A value outside the control's range
// is INVALID_ARGUMENT naming it; a setting for an absent control is noted in the result (and in
// the log), not an error. Asking for auto exposure and a fixed exposure at once is invalid.
StatusOr<std::vector<ControlState>> ApplyControls(int fd, const std::string& device, const ControlSettings& settings);

}  // namespace px::v4l2
