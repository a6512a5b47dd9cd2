#include "drivers/v4l2/v4l2_discovery.h"

#include <linux/videodev2.h>

#include <algorithm>
#include <cstdio>
#include <system_error>

#include "drivers/v4l2/v4l2_io.h"

namespace px::v4l2 {
namespace {

namespace fs = std::filesystem;

std::string Hex(uint32_t value) {
  char text[16];
  std::snprintf(text, sizeof(text), "0x%08x", value);
  return text;
}

// Why a node with these capabilities is not a camera we can use; empty when it is.
std::string UnusableReason(uint32_t caps) {
  const std::string suffix = " (device caps " + Hex(caps) + ")";
  if (caps & V4L2_CAP_VIDEO_CAPTURE) {
    if (!(caps & V4L2_CAP_STREAMING)) return "video capture without streaming I/O (read() only)" + suffix;
    return "";
  }
  if (caps & V4L2_CAP_VIDEO_CAPTURE_MPLANE) return "multi-planar video capture only (not supported)" + suffix;
  if (caps & V4L2_CAP_META_CAPTURE) return "metadata capture node, not images" + suffix;
  if (caps & (V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_VIDEO_OUTPUT_MPLANE)) return "video output only" + suffix;
  if (caps & V4L2_CAP_VIDEO_M2M) return "memory-to-memory codec or converter" + suffix;
  return "no video capture capability" + suffix;
}

// video2 before video10.
int NodeNumber(const std::string& name) {
  try {
    return std::stoi(name.substr(5));
  } catch (...) {
    return 1 << 30;
  }
}

}  // namespace

StatusOr<DeviceInfo> QueryDevice(int fd, const std::string& path) {
  v4l2_capability cap{};
  if (Ioctl(fd, VIDIOC_QUERYCAP, &cap) != 0) {
    if (errno == ENOTTY) return FailedPreconditionError("not a V4L2 device (VIDIOC_QUERYCAP: not supported)");
    return ErrnoStatus(path, "VIDIOC_QUERYCAP", errno);
  }
  // device_caps describes this node; capabilities covers the whole physical device.
  const uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  if (std::string reason = UnusableReason(caps); !reason.empty()) return FailedPreconditionError(reason);
  DeviceInfo info;
  info.path = path;
  info.name = reinterpret_cast<const char*>(cap.card);
  info.driver = reinterpret_cast<const char*>(cap.driver);
  info.bus_info = reinterpret_cast<const char*>(cap.bus_info);
  info.device_caps = caps;
  PX_ASSIGN_OR_RETURN(info.formats, EnumerateFormats(fd, path));
  return info;
}

StatusOr<Discovery> DiscoverDevices(const fs::path& dev_dir) {
  std::error_code error;
  fs::directory_iterator it(dev_dir, error);
  if (error) return NotFoundError("v4l2: cannot list " + dev_dir.string() + ": " + error.message());
  std::vector<std::string> names;
  for (const auto& entry : it) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("video", 0) == 0) names.push_back(name);
  }
  std::sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) {
    return NodeNumber(a) != NodeNumber(b) ? NodeNumber(a) < NodeNumber(b) : a < b;
  });

  Discovery discovery;
  for (const std::string& name : names) {
    const std::string path = (dev_dir / name).string();
    auto fd = OpenDevice(path);
    if (!fd.ok()) {
      discovery.skipped.push_back({path, fd.status().message()});
      continue;
    }
    auto info = QueryDevice(fd->get(), path);
    if (!info.ok()) {
      discovery.skipped.push_back({path, info.status().message()});
      continue;
    }
    discovery.cameras.push_back(std::move(info).value());
  }
  return discovery;
}

}  // namespace px::v4l2
