// Finding cameras: every /dev/video* node is asked VIDIOC_QUERYCAP; single-planar video-capture
// devices that can stream are kept with their formats and sizes, the others are listed with the
// reason they were skipped (so "no camera found" can say why).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "drivers/v4l2/v4l2_formats.h"
#include "pipeline/core/status.h"

namespace px::v4l2 {

struct DeviceInfo {
  std::string path;      // "/dev/video0"
  std::string name;      // QUERYCAP card, "HD Pro Webcam C920"
  std::string driver;    // "uvcvideo"
  std::string bus_info;  // "usb-0000:00:14.0-1"
  uint32_t device_caps = 0;
  std::vector<DeviceFormat> formats;
};

struct SkippedNode {
  std::string path;
  std::string reason;  // "video output only (device caps 0x04200002)", "open: Permission denied"
};

struct Discovery {
  std::vector<DeviceInfo> cameras;
  std::vector<SkippedNode> skipped;
};

// Asks one open node what it is. FAILED_PRECONDITION (with the reason) for a node that is not a
// single-planar streaming video-capture device; errno errors as ErrnoStatus.
StatusOr<DeviceInfo> QueryDevice(int fd, const std::string& path);

// Every video* node under `dev_dir`, in natural order (video2 before video10). Only a missing
// or unreadable `dev_dir` is an error; a node that cannot be opened is skipped with its reason.
StatusOr<Discovery> DiscoverDevices(const std::filesystem::path& dev_dir = "/dev");

}  // namespace px::v4l2
