#include "drivers/v4l2/v4l2_controls.h"

#include <linux/videodev2.h>

#include "drivers/v4l2/v4l2_io.h"
#include "pipeline/core/log.h"

namespace px::v4l2 {
namespace {

constexpr uint32_t kAutoExposure = V4L2_CID_EXPOSURE_AUTO;
constexpr uint32_t kExposure = V4L2_CID_EXPOSURE_ABSOLUTE;
constexpr uint32_t kGain = V4L2_CID_GAIN;

std::string ControlName(uint32_t id) {
  switch (id) {
    case kAutoExposure:
      return "auto_exposure";
    case kExposure:
      return "exposure";
    case kGain:
      return "gain";
    default:
      return "control " + std::to_string(id);
  }
}

std::string CidName(uint32_t id) {
  switch (id) {
    case kAutoExposure:
      return "V4L2_CID_EXPOSURE_AUTO";
    case kExposure:
      return "V4L2_CID_EXPOSURE_ABSOLUTE";
    case kGain:
      return "V4L2_CID_GAIN";
    default:
      return std::to_string(id);
  }
}

StatusOr<ControlState> Query(int fd, const std::string& device, uint32_t id) {
  ControlState state;
  state.id = id;
  state.name = ControlName(id);
  v4l2_queryctrl query{};
  query.id = id;
  if (Ioctl(fd, VIDIOC_QUERYCTRL, &query) != 0) {
    // EINVAL is V4L2's "no such control"; ENOTTY a device without controls at all.
    if (errno == EINVAL || errno == ENOTTY) return state;
    return ErrnoStatus(device, "VIDIOC_QUERYCTRL " + CidName(id), errno);
  }
  if (query.flags & V4L2_CTRL_FLAG_DISABLED) return state;
  state.present = true;
  state.read_only = (query.flags & V4L2_CTRL_FLAG_READ_ONLY) != 0;
  state.minimum = query.minimum;
  state.maximum = query.maximum;
  state.step = query.step;
  state.default_value = query.default_value;
  if (query.flags & V4L2_CTRL_FLAG_INACTIVE) state.note = "inactive";
  v4l2_control control{};
  control.id = id;
  if (Ioctl(fd, VIDIOC_G_CTRL, &control) != 0) {
    if (errno != EACCES) return ErrnoStatus(device, "VIDIOC_G_CTRL " + CidName(id), errno);  // EACCES: write-only
  } else {
    state.value = control.value;
  }
  return state;
}

Status Set(int fd, const std::string& device, ControlState* state, int32_t value) {
  if (state->read_only) {
    return InvalidArgumentError("v4l2:" + device + ": " + state->name + " is read-only on this device");
  }
  if (value < state->minimum || value > state->maximum) {
    return InvalidArgumentError("v4l2:" + device + ": " + state->name + " " + std::to_string(value) + " is not in [" +
                                std::to_string(state->minimum) + ", " + std::to_string(state->maximum) + "] (" +
                                CidName(state->id) + ")");
  }
  v4l2_control control{};
  control.id = state->id;
  control.value = value;
  if (Ioctl(fd, VIDIOC_S_CTRL, &control) != 0) {
    if (errno == ERANGE || errno == EINVAL) {
      return InvalidArgumentError("v4l2:" + device + ": " + state->name + " " + std::to_string(value) +
                                  " refused by the device (" + CidName(state->id) + ")");
    }
    return ErrnoStatus(device, "VIDIOC_S_CTRL " + CidName(state->id), errno);
  }
  control.value = 0;
  if (Ioctl(fd, VIDIOC_G_CTRL, &control) != 0) return ErrnoStatus(device, "VIDIOC_G_CTRL " + CidName(state->id), errno);
  state->value = control.value;
  state->note = "set to " + std::to_string(value);
  return OkStatus();
}

void NoteAbsent(const std::string& device, ControlState* state, int32_t wanted) {
  state->note = "absent: " + state->name + " " + std::to_string(wanted) + " not applied";
  Logger("v4l2")->warn(
      "v4l2:{}: no {} control ({}); {} {} not applied", device, state->name, CidName(state->id), state->name, wanted);
}

}  // namespace

std::string ControlState::ToString() const {
  if (!present) return name + ": " + (note.empty() ? "absent" : note);
  std::string text =
      name + "=" + std::to_string(value) + " [" + std::to_string(minimum) + ", " + std::to_string(maximum) + "]";
  if (!note.empty()) text += " (" + note + ")";
  return text;
}

StatusOr<std::vector<ControlState>> ReadControls(int fd, const std::string& device) {
  std::vector<ControlState> states;
  for (uint32_t id : {kAutoExposure, kExposure, kGain}) {
    PX_ASSIGN_OR_RETURN(ControlState state, Query(fd, device, id));
    states.push_back(std::move(state));
  }
  return states;
}

StatusOr<std::vector<ControlState>> ApplyControls(int fd, const std::string& device, const ControlSettings& settings) {
  if (settings.exposure && settings.auto_exposure.value_or(false)) {
    return InvalidArgumentError("v4l2:" + device + ": exposure " + std::to_string(*settings.exposure) +
                                " conflicts with auto exposure on");
  }
  PX_ASSIGN_OR_RETURN(std::vector<ControlState> states, ReadControls(fd, device));
  ControlState& auto_exposure = states[0];
  ControlState& exposure = states[1];
  ControlState& gain = states[2];

  // A fixed exposure needs manual mode first: UVC cameras refuse EXPOSURE_ABSOLUTE in auto mode.
  std::optional<bool> want_auto = settings.auto_exposure;
  if (settings.exposure) want_auto = false;
  if (want_auto) {
    if (!auto_exposure.present) {
      if (settings.auto_exposure)
        NoteAbsent(device, &auto_exposure, *want_auto ? V4L2_EXPOSURE_AUTO : V4L2_EXPOSURE_MANUAL);
    } else if (!*want_auto) {
      PX_RETURN_IF_ERROR(Set(fd, device, &auto_exposure, V4L2_EXPOSURE_MANUAL));
    } else {
      // Many webcams offer only manual and aperture priority (their "auto").
      Status full_auto = Set(fd, device, &auto_exposure, V4L2_EXPOSURE_AUTO);
      if (!full_auto.ok()) {
        if (full_auto.code() != StatusCode::kInvalidArgument) return full_auto;
        PX_RETURN_IF_ERROR(Set(fd, device, &auto_exposure, V4L2_EXPOSURE_APERTURE_PRIORITY));
      }
    }
  }
  if (settings.exposure) {
    if (exposure.present) {
      PX_RETURN_IF_ERROR(Set(fd, device, &exposure, *settings.exposure));
    } else {
      NoteAbsent(device, &exposure, *settings.exposure);
    }
  }
  if (settings.gain) {
    if (gain.present) {
      PX_RETURN_IF_ERROR(Set(fd, device, &gain, *settings.gain));
    } else {
      NoteAbsent(device, &gain, *settings.gain);
    }
  }
  return states;
}

}  // namespace px::v4l2
