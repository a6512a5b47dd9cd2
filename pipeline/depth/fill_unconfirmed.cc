#include "pipeline/depth/fill_unconfirmed.h"

#include <algorithm>

#include "pipeline/core/check.h"

namespace px::depth {

int FillUnconfirmedFromBackground(const cv::Mat& confirmed, cv::Mat* depth_m) {
  PX_CHECK(confirmed.type() == CV_8UC1 && depth_m->type() == CV_32FC1 && confirmed.size() == depth_m->size());
  int changed = 0;
  for (int y = 0; y < depth_m->rows; ++y) {
    const uint8_t* c = confirmed.ptr<uint8_t>(y);
    float* z = depth_m->ptr<float>(y);
    const auto known = [&](int x) { return c[x] != 0 && z[x] > 0; };
    int x = 0;
    while (x < depth_m->cols) {
      if (known(x)) {
        ++x;
        continue;
      }
      const int start = x;
      while (x < depth_m->cols && !known(x)) ++x;
      const float before = start > 0 ? z[start - 1] : 0.0f;
      const float after = x < depth_m->cols ? z[x] : 0.0f;
      const float fill = std::max(before, after);  // the farther; 0 (none) loses to any depth
      if (fill <= 0) continue;
      for (int i = start; i < x; ++i) {
        changed += z[i] != fill;
        z[i] = fill;
      }
    }
  }
  return changed;
}

}  // namespace px::depth
