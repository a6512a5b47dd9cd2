// The soft z-buffer weight (paper eq. 1) on a relative depth gap: 1 for gaps up to a quarter of
// the band, a raised cosine down to 0 at the band, 0 beyond.
#pragma once

#include <cmath>

namespace px::render {

inline float SoftZWeight(float relative_gap, float band) {
  const float full = 0.25f * band;
  if (relative_gap <= full) return 1.0f;
  if (relative_gap >= band) return 0.0f;
  constexpr float kPi = 3.14159265f;
  return 0.5f * (1.0f + std::cos(kPi * (relative_gap - full) / (band - full)));
}

}  // namespace px::render
