#include "eval/render/crack_measure.h"

#include <array>
#include <cmath>

namespace px::eval {
namespace {

bool HasTruth(float z) { return std::isfinite(z) && z > 0; }

}  // namespace

CrackReport MeasureCracks(const cv::Mat& rendered_depth_m,
                          const cv::Mat& true_depth_m,
                          const CrackMeasureOptions& options,
                          cv::Mat* cracks) {
  CV_Assert(rendered_depth_m.type() == CV_32F && true_depth_m.type() == CV_32F &&
            rendered_depth_m.size() == true_depth_m.size());
  const int width = true_depth_m.cols, height = true_depth_m.rows;
  const float tolerance = static_cast<float>(options.far_fraction);
  const auto rendered = [&](int x, int y) { return rendered_depth_m.at<float>(y, x); };
  const auto truth = [&](int x, int y) { return true_depth_m.at<float>(y, x); };
  const auto near = [&](int x, int y) {
    const float z = truth(x, y);
    return HasTruth(z) && std::abs(rendered(x, y) - z) <= tolerance * z;
  };
  // Row, column and both diagonals.
  constexpr std::array<std::array<int, 2>, 4> kDirections = {{{1, 0}, {0, 1}, {1, 1}, {1, -1}}};
  cv::Mat map = cv::Mat::zeros(height, width, CV_8U);
  CrackReport report;
  int with_truth = 0;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const float z = truth(x, y);
      if (!HasTruth(z)) continue;
      ++with_truth;
      if (!(rendered(x, y) > (1 + tolerance) * z)) continue;
      // A near side at offset -a and +b along a direction, the gap between them (a + b - 1 pixels)
      // at most max_gap_px, both on the pixel's own true surface.
      const auto side = [&](int sx, int sy) {
        return sx >= 0 && sy >= 0 && sx < width && sy < height && near(sx, sy) &&
               std::abs(truth(sx, sy) - z) <= tolerance * z;
      };
      bool crack = false;
      for (const auto& d : kDirections) {
        for (int a = 1; a <= options.max_gap_px && !crack; ++a) {
          if (!side(x - a * d[0], y - a * d[1])) continue;
          for (int b = 1; a + b - 1 <= options.max_gap_px && !crack; ++b) {
            crack = side(x + b * d[0], y + b * d[1]);
          }
        }
        if (crack) break;
      }
      if (crack) {
        map.at<uint8_t>(y, x) = 255;
        ++report.crack_pixels;
      }
    }
  }
  report.crack_fraction = with_truth > 0 ? static_cast<double>(report.crack_pixels) / with_truth : 0.0;
  if (cracks != nullptr) *cracks = map;
  return report;
}

}  // namespace px::eval
