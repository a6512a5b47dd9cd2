#include "pipeline/direct/clip_timing.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace px {
namespace {

int MoveFrames(double fps, double duration_s) { return std::max(1, static_cast<int>(std::lround(fps * duration_s))); }

}  // namespace

std::string_view ClipStyleName(ClipStyle style) {
  switch (style) {
    case ClipStyle::kOnce:
      return "once";
    case ClipStyle::kLoop:
      return "loop";
    case ClipStyle::kBoomerang:
      return "boomerang";
  }
  return "once";
}

StatusOr<ClipStyle> ParseClipStyle(std::string_view name) {
  for (ClipStyle style : {ClipStyle::kOnce, ClipStyle::kLoop, ClipStyle::kBoomerang}) {
    if (ClipStyleName(style) == name) return style;
  }
  return InvalidArgumentError("'" + std::string(name) + "' is not one of once, loop, boomerang");
}

std::string_view ClipEaseName(ClipEase ease) { return ease == ClipEase::kLinear ? "linear" : "smooth"; }

StatusOr<ClipEase> ParseClipEase(std::string_view name) {
  if (name == "linear") return ClipEase::kLinear;
  if (name == "smooth") return ClipEase::kSmooth;
  return InvalidArgumentError("'" + std::string(name) + "' is not one of linear, smooth");
}

Status ClipTiming::Validate() const {
  if (!(hold_s >= 0 && hold_s <= 60))
    return InvalidArgumentError("hold_s: " + std::to_string(hold_s) + " is not in [0, 60]");
  if (hold_s > 0 && style != ClipStyle::kOnce) {
    return InvalidArgumentError("hold_s: only a clip played once holds its last frame (style is " +
                                std::string(ClipStyleName(style)) + ")");
  }
  return OkStatus();
}

double Ease(ClipEase ease, double s) {
  s = std::clamp(s, 0.0, 1.0);
  return ease == ClipEase::kLinear ? s : s * s * (3 - 2 * s);
}

int ClipTiming::NumFrames(double fps, double duration_s) const {
  const int m = MoveFrames(fps, duration_s);
  switch (style) {
    case ClipStyle::kOnce:
      return m + static_cast<int>(std::lround(fps * hold_s));
    case ClipStyle::kLoop:
      return std::max(2, m);
    case ClipStyle::kBoomerang:
      return 2 * std::max(2, m) - 1;
  }
  return m;
}

double ClipTiming::FrameTime(int index, double fps, double duration_s) const {
  const int n = NumFrames(fps, duration_s);
  index = std::clamp(index, 0, n - 1);
  switch (style) {
    case ClipStyle::kOnce: {
      const int m = MoveFrames(fps, duration_s);
      if (m <= 1) return 0.0;
      return Ease(ease, static_cast<double>(std::min(index, m - 1)) / (m - 1));
    }
    case ClipStyle::kLoop: {
      // Out over the first half of the cycle, back over the second; frame n would be frame 0.
      // Frames i and n - i are the same place: computed from the same integer, so equal exactly.
      const int k = std::min(index, n - index);
      return Ease(ease, 2.0 * k / n);
    }
    case ClipStyle::kBoomerang: {
      const int m = (n + 1) / 2;
      const int k = index < m ? index : n - 1 - index;
      return Ease(ease, static_cast<double>(k) / (m - 1));
    }
  }
  return 0.0;
}

}  // namespace px
