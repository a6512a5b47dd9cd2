#include "drivers/v4l2/v4l2_formats.h"

#include <linux/videodev2.h>

#include <algorithm>
#include <cctype>

#include "drivers/v4l2/v4l2_io.h"
#include "pipeline/core/size_text.h"

namespace px::v4l2 {
namespace {

struct FourccMapping {
  PixelFormat format;
  uint32_t fourcc;
};

constexpr FourccMapping kMappings[] = {
    {PixelFormat::kRgb888, V4L2_PIX_FMT_RGB24},
    {PixelFormat::kBgr888, V4L2_PIX_FMT_BGR24},
    {PixelFormat::kGray8, V4L2_PIX_FMT_GREY},
    {PixelFormat::kYuyv, V4L2_PIX_FMT_YUYV},
    {PixelFormat::kNv12, V4L2_PIX_FMT_NV12},
    {PixelFormat::kBayerRggb8, V4L2_PIX_FMT_SRGGB8},
};

// Fills the sizes of one format; devices that cannot enumerate sizes are left without.
Status EnumerateSizes(int fd, const std::string& device, DeviceFormat* format) {
  for (uint32_t index = 0;; ++index) {
    v4l2_frmsizeenum size{};
    size.index = index;
    size.pixel_format = format->fourcc;
    if (Ioctl(fd, VIDIOC_ENUM_FRAMESIZES, &size) != 0) {
      if (errno == EINVAL || errno == ENOTTY) break;  // end of list, or not supported
      return ErrnoStatus(device, "VIDIOC_ENUM_FRAMESIZES " + FourccName(format->fourcc), errno);
    }
    if (size.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
      format->sizes.push_back({static_cast<int>(size.discrete.width), static_cast<int>(size.discrete.height)});
      continue;
    }
    format->min_size = FrameSize{static_cast<int>(size.stepwise.min_width), static_cast<int>(size.stepwise.min_height)};
    format->max_size = FrameSize{static_cast<int>(size.stepwise.max_width), static_cast<int>(size.stepwise.max_height)};
    format->step_width = static_cast<int>(size.stepwise.step_width);
    format->step_height = static_cast<int>(size.stepwise.step_height);
    break;  // stepwise and continuous have a single entry
  }
  std::sort(format->sizes.begin(), format->sizes.end(), [](const FrameSize& a, const FrameSize& b) {
    return int64_t{a.width} * a.height > int64_t{b.width} * b.height;
  });
  return OkStatus();
}

}  // namespace

std::string FourccName(uint32_t fourcc) {
  std::string name;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((fourcc >> (8 * i)) & 0xff);
    name += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  }
  while (!name.empty() && name.back() == ' ') name.pop_back();
  return name;
}

uint32_t FourccFor(PixelFormat format) {
  for (const auto& mapping : kMappings) {
    if (mapping.format == format) return mapping.fourcc;
  }
  return 0;
}

std::optional<PixelFormat> PixelFormatForFourcc(uint32_t fourcc) {
  for (const auto& mapping : kMappings) {
    if (mapping.fourcc == fourcc) return mapping.format;
  }
  return std::nullopt;
}

bool DriverReadsFourcc(uint32_t fourcc) {
  return PixelFormatForFourcc(fourcc).has_value() || fourcc == V4L2_PIX_FMT_MJPEG;
}

std::string DriverFourccList() {
  std::string list;
  for (const auto& mapping : kMappings) list += FourccName(mapping.fourcc) + ", ";
  return list + FourccName(V4L2_PIX_FMT_MJPEG);
}

std::string DeviceFormat::ToString() const {
  std::string text = FourccName(fourcc);
  if (!sizes.empty()) {
    for (size_t i = 0; i < sizes.size(); ++i) text += (i == 0 ? " " : ",") + SizeText(sizes[i].width, sizes[i].height);
  } else if (min_size && max_size) {
    text += " " + SizeText(min_size->width, min_size->height) + ".." + SizeText(max_size->width, max_size->height) +
            "/" + std::to_string(step_width) + "x" + std::to_string(step_height);
  } else {
    text += " (sizes not listed)";
  }
  return text;
}

StatusOr<std::vector<DeviceFormat>> EnumerateFormats(int fd, const std::string& device) {
  std::vector<DeviceFormat> formats;
  for (uint32_t index = 0;; ++index) {
    v4l2_fmtdesc desc{};
    desc.index = index;
    desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (Ioctl(fd, VIDIOC_ENUM_FMT, &desc) != 0) {
      if (errno == EINVAL) break;  // end of the list
      return ErrnoStatus(device, "VIDIOC_ENUM_FMT", errno);
    }
    DeviceFormat format;
    format.fourcc = desc.pixelformat;
    format.description = reinterpret_cast<const char*>(desc.description);
    format.compressed = (desc.flags & V4L2_FMT_FLAG_COMPRESSED) != 0;
    PX_RETURN_IF_ERROR(EnumerateSizes(fd, device, &format));
    formats.push_back(std::move(format));
  }
  return formats;
}

std::string DescribeFormats(const std::vector<DeviceFormat>& formats) {
  if (formats.empty()) return "no formats";
  std::string text;
  for (const auto& format : formats) text += (text.empty() ? "" : "; ") + format.ToString();
  return text;
}

}  // namespace px::v4l2
