// How a clip plays its camera path in time: the style (once, loop, boomerang), the easing of
// the move (linear as in the paper, or smooth: easing in and out so the camera neither starts
// nor stops abruptly) and a hold on the last frame. It maps each clip frame to a normalised time
// t along the path; the path's positions are the same whatever the timing, so the valid-viewpoint
// search and its H(V) checks hold for every style.
//   once       the move over duration_s, then hold_s on its last frame;
//   loop       one seamless cycle in duration_s: out along the path and back, the last frame
//              one step before the first, so a player looping it shows no jump;
//   boomerang  the move over duration_s, then the same frames backwards (ends where it began).
#pragma once

#include <string_view>

#include "pipeline/core/status.h"

namespace px {

enum class ClipStyle { kOnce, kLoop, kBoomerang };
enum class ClipEase { kLinear, kSmooth };

std::string_view ClipStyleName(ClipStyle style);  // "once", "loop", "boomerang"
StatusOr<ClipStyle> ParseClipStyle(std::string_view name);
std::string_view ClipEaseName(ClipEase ease);  // "linear", "smooth"
StatusOr<ClipEase> ParseClipEase(std::string_view name);

struct ClipTiming {
  ClipStyle style = ClipStyle::kOnce;
  ClipEase ease = ClipEase::kSmooth;
  double hold_s = 0;  // once: seconds the last frame is held after the move, [0, 60]

  Status Validate() const;
  // Frames of a clip whose move takes `duration_s` at `fps`: once m + round(fps * hold_s),
  // loop m, boomerang 2m - 1 (m = round(fps * duration_s), at least 2 where the style needs it).
  int NumFrames(double fps, double duration_s) const;
  // Normalised path time of frame `index` (clamped to the clip). Frames that show the same
  // place get exactly the same t, so a renderer may reuse them.
  double FrameTime(int index, double fps, double duration_s) const;
};

// The easing curve on [0, 1]: identity, or smoothstep (3s^2 - 2s^3: zero speed at both ends,
// 1.5 times the linear speed at the middle).
double Ease(ClipEase ease, double s);

}  // namespace px
