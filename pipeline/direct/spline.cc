#include "pipeline/direct/spline.h"

#include <algorithm>

#include "pipeline/core/check.h"

namespace px::direct {

std::pair<size_t, double> KeySpan(const std::vector<double>& times, double t) {
  PX_CHECK(times.size() >= 2) << "interpolation needs two keys, got " << times.size();
  t = std::clamp(t, times.front(), times.back());
  size_t i = 0;
  while (i + 2 < times.size() && t > times[i + 1]) ++i;
  const double span = times[i + 1] - times[i];
  const double fraction = span > 0 ? (t - times[i]) / span : 0.0;
  return {i, std::clamp(fraction, 0.0, 1.0)};
}

}  // namespace px::direct
