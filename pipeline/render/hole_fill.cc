#include "pipeline/render/hole_fill.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "pipeline/core/check.h"

namespace px::render {

double HoleScore(const cv::Mat& coverage, double exponent) {
  PX_CHECK(coverage.type() == CV_8U) << "coverage type " << coverage.type();
  if (coverage.empty() || cv::countNonZero(coverage) == static_cast<int>(coverage.total())) return 0.0;
  cv::Mat holes = coverage == 0;
  if (cv::countNonZero(holes) == static_cast<int>(holes.total())) {
    return std::pow(std::hypot(coverage.cols, coverage.rows), exponent);
  }
  cv::Mat distance;
  // distanceTransform measures to the nearest zero pixel: the covered ones must be zero.
  cv::distanceTransform(holes, distance, cv::DIST_L2, cv::DIST_MASK_5);
  double sum = 0;
  for (int y = 0; y < distance.rows; ++y) {
    const float* row = distance.ptr<float>(y);
    for (int x = 0; x < distance.cols; ++x) {
      if (row[x] > 0) sum += std::pow(static_cast<double>(row[x]), exponent);
    }
  }
  return sum / static_cast<double>(coverage.total());
}

namespace {

// Chebyshev distance of every unknown pixel to the nearest known one (0 on known pixels).
cv::Mat ChebyshevDistance(const cv::Mat& known) {
  cv::Mat distance;
  cv::distanceTransform(known == 0, distance, cv::DIST_C, 3);
  return distance;
}

}  // namespace

HoleFillReport FillHolesReverseSoftZ(const SoftZ& soft_z,
                                     int radius_px,
                                     int max_passes,
                                     cv::Mat* known,
                                     cv::Mat* colour,
                                     cv::Mat* depth,
                                     const cv::Mat* only) {
  PX_CHECK(known != nullptr && colour != nullptr && depth != nullptr) << "FillHolesReverseSoftZ needs outputs";
  PX_CHECK(known->type() == CV_8U && colour->type() == CV_32FC3 && depth->type() == CV_32F)
      << "FillHolesReverseSoftZ types " << known->type() << " " << colour->type() << " " << depth->type();
  PX_CHECK(known->size() == colour->size() && known->size() == depth->size()) << "FillHolesReverseSoftZ sizes differ";
  HoleFillReport report;
  const int width = known->cols, height = known->rows;
  const int total = width * height;
  const int known_count = cv::countNonZero(*known);
  report.hole_pixels = total - known_count;
  if (only != nullptr) report.hole_pixels = cv::countNonZero((*known == 0) & (*only != 0));
  if (report.hole_pixels == 0) return report;
  if (known_count == 0) {
    report.unfilled = report.hole_pixels;
    return report;
  }
  radius_px = std::max(1, radius_px);
  // Pass of each hole pixel: ceil(Chebyshev distance / radius).
  const cv::Mat distance = ChebyshevDistance(*known);
  std::vector<std::vector<cv::Point>> by_pass;
  for (int y = 0; y < height; ++y) {
    const float* d = distance.ptr<float>(y);
    const uint8_t* wanted = only != nullptr ? only->ptr<uint8_t>(y) : nullptr;
    for (int x = 0; x < width; ++x) {
      if (d[x] <= 0 || (wanted != nullptr && wanted[x] == 0)) continue;
      const int pass = static_cast<int>(std::ceil(d[x] / radius_px - 1e-4f));
      if (static_cast<int>(by_pass.size()) < pass) by_pass.resize(pass);
      by_pass[pass - 1].emplace_back(x, y);
    }
  }
  std::vector<cv::Vec3f> new_colour;
  std::vector<float> new_depth;
  std::vector<uint8_t> filled;
  for (size_t pass = 0; pass < by_pass.size(); ++pass) {
    if (max_passes > 0 && static_cast<int>(pass) >= max_passes) break;
    const std::vector<cv::Point>& holes = by_pass[pass];
    new_colour.assign(holes.size(), cv::Vec3f(0, 0, 0));
    new_depth.assign(holes.size(), 0.0f);
    filled.assign(holes.size(), 0);
    cv::parallel_for_(cv::Range(0, static_cast<int>(holes.size())), [&](const cv::Range& range) {
      for (int i = range.start; i < range.end; ++i) {
        const cv::Point p = holes[i];
        const int x0 = std::max(0, p.x - radius_px), x1 = std::min(width - 1, p.x + radius_px);
        const int y0 = std::max(0, p.y - radius_px), y1 = std::min(height - 1, p.y + radius_px);
        float z_far = -std::numeric_limits<float>::infinity();
        for (int y = y0; y <= y1; ++y) {
          const uint8_t* k = known->ptr<uint8_t>(y);
          const float* z = depth->ptr<float>(y);
          for (int x = x0; x <= x1; ++x) {
            if (k[x] != 0) z_far = std::max(z_far, z[x]);
          }
        }
        if (!(z_far > -std::numeric_limits<float>::infinity())) continue;
        float sum_w = 0, sum_z = 0;
        cv::Vec3f sum_c(0, 0, 0);
        for (int y = y0; y <= y1; ++y) {
          const uint8_t* k = known->ptr<uint8_t>(y);
          const float* z = depth->ptr<float>(y);
          const cv::Vec3f* c = colour->ptr<cv::Vec3f>(y);
          for (int x = x0; x <= x1; ++x) {
            if (k[x] == 0) continue;
            const float w = soft_z.Weight(z_far - z[x]);
            if (w <= 0) continue;
            sum_w += w;
            sum_z += w * z[x];
            sum_c += w * c[x];
          }
        }
        if (!(sum_w > 0)) continue;
        new_colour[i] = sum_c * (1.0f / sum_w);
        new_depth[i] = sum_z / sum_w;
        filled[i] = 1;
      }
    });
    int count = 0;
    for (size_t i = 0; i < holes.size(); ++i) {
      if (!filled[i]) continue;
      colour->at<cv::Vec3f>(holes[i]) = new_colour[i];
      depth->at<float>(holes[i]) = new_depth[i];
      known->at<uint8_t>(holes[i]) = 255;
      ++count;
    }
    ++report.passes;
    if (pass == 0) {
      report.first_pass += count;
    } else {
      report.later_passes += count;
    }
  }
  report.unfilled = report.hole_pixels - report.first_pass - report.later_passes;
  return report;
}

cv::Mat SmallHoles(const cv::Mat& known, int radius_px) {
  cv::Mat small = cv::Mat::zeros(known.size(), CV_8U);
  const cv::Mat holes = known == 0;
  if (cv::countNonZero(holes) == 0 || cv::countNonZero(known) == 0) return small;
  const cv::Mat distance = ChebyshevDistance(known);
  cv::Mat labels;
  const int count = cv::connectedComponents(holes, labels, 8, CV_32S);
  std::vector<float> max_distance(count, 0.0f);
  for (int y = 0; y < known.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const float* d = distance.ptr<float>(y);
    for (int x = 0; x < known.cols; ++x) max_distance[l[x]] = std::max(max_distance[l[x]], d[x]);
  }
  for (int y = 0; y < known.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    uint8_t* out = small.ptr<uint8_t>(y);
    for (int x = 0; x < known.cols; ++x) {
      if (l[x] > 0 && max_distance[l[x]] <= static_cast<float>(radius_px) + 1e-4f) out[x] = 255;
    }
  }
  return small;
}

}  // namespace px::render
