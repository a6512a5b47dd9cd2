#include "pipeline/direct/output_frame.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>

namespace px {
namespace {

int Even(double value) { return std::max(2, 2 * static_cast<int>(std::lround(value / 2))); }

}  // namespace

Status OutputFrameOptions::Validate() const {
  const bool explicit_size = width > 0;
  if (explicit_size && !(width >= 16 && width <= 8192 && height >= 16 && height <= 8192)) {
    return InvalidArgumentError("output size " + std::to_string(width) + "x" + std::to_string(height) +
                                " is not within 16..8192 on both sides");
  }
  if (!explicit_size && height != 0 && !(height >= 16 && height <= 8192)) {
    return InvalidArgumentError("output height " + std::to_string(height) + " is not within 16..8192");
  }
  if (width < 0 || !(aspect == 0 || (aspect >= 0.1 && aspect <= 10))) {
    return InvalidArgumentError("output aspect " + std::to_string(aspect) + " is not within 0.1..10");
  }
  return OkStatus();
}

Status ParseOutputSize(std::string_view text, OutputFrameOptions* options) {
  int width = 0;
  int height = 0;
  const std::string s(text);
  // from_chars: digits only, and a number too large for an int is an error, not overflow.
  const char* const end = s.data() + s.size();
  const auto [after_width, width_error] = std::from_chars(s.data(), end, width);
  bool parsed = width_error == std::errc() && after_width != end && *after_width == 'x';
  if (parsed) {
    const auto [after_height, height_error] = std::from_chars(after_width + 1, end, height);
    parsed = height_error == std::errc() && after_height == end;
  }
  if (!parsed || s.empty() || !std::isdigit(static_cast<unsigned char>(s.front()))) {
    return InvalidArgumentError("size '" + s + "': want WIDTHxHEIGHT, e.g. 1080x1920");
  }
  options->width = width;
  options->height = height;
  return options->Validate();
}

Status ParseOutputAspect(std::string_view text, OutputFrameOptions* options) {
  const std::string s(text);
  if (s == "source") {
    options->aspect = 0;
    return OkStatus();
  }
  double w = 0;
  double h = 0;
  char tail = 0;
  if (std::sscanf(s.c_str(), "%lf:%lf%c", &w, &h, &tail) != 2 || !(w > 0 && h > 0)) {
    return InvalidArgumentError("aspect '" + s + "': want W:H (16:9, 9:16, 1:1, 4:5) or source");
  }
  options->aspect = w / h;
  return options->Validate();
}

OutputSize ResolveOutputSize(const OutputFrameOptions& options, int source_width, int source_height) {
  if (options.width > 0) return {Even(options.width), Even(options.height)};
  const int height = options.height > 0 ? options.height : source_height;
  const double aspect = options.aspect > 0 ? options.aspect : static_cast<double>(source_width) / source_height;
  if (options.height == 0 && options.aspect == 0) return {source_width, source_height};  // as it is
  return {Even(height * aspect), Even(height)};
}

CameraModel FrameOutputCamera(const CameraModel& source, OutputSize size, double* scale) {
  CameraModel out = source.WithoutDistortion();
  // The widest crop of the output's aspect inside the source's field: the tighter of the two.
  const double s =
      std::max(static_cast<double>(size.width) / source.width, static_cast<double>(size.height) / source.height);
  out.fx = source.fx * s;
  out.fy = source.fy * s;
  // Pixel centres at integers: the frame's centre is (width - 1) / 2 on both sides.
  out.cx = (source.cx - 0.5 * (source.width - 1)) * s + 0.5 * (size.width - 1);
  out.cy = (source.cy - 0.5 * (source.height - 1)) * s + 0.5 * (size.height - 1);
  out.width = size.width;
  out.height = size.height;
  if (scale != nullptr) *scale = s;
  return out;
}

}  // namespace px
