#include "pipeline/render/hole_fill.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "pipeline/core/check.h"
#include "pipeline/render/soft_z.h"

namespace px::render {

double HoleScore(const cv::Mat& coverage, double exponent) {
  PX_CHECK(coverage.type() == CV_8U) << "coverage type " << coverage.type();
  if (coverage.empty() || cv::countNonZero(coverage) == static_cast<int>(coverage.total())) return 0.0;
  cv::Mat distance;
  // distanceTransform measures to the nearest zero pixel: the covered ones must be zero.
  cv::Mat holes = coverage == 0;
  if (cv::countNonZero(holes) == static_cast<int>(holes.total())) {
    // Nothing covered at all: every pixel is as far from valid data as the image is large.
    return std::pow(std::hypot(coverage.cols, coverage.rows), exponent);
  }
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

// Fills each listed hole pixel that has usable known pixels within `radius_px`; marks it in
// `filled`. Usable: within the relative `band` of the depth its hole's background lies at
// (`background_z[label]`, reverse soft z: a disocclusion reveals background, so the foreground
// must not bleed in), or any known pixel when `ignore_depth`. Nearer pixels weigh more. Reads
// only pixels known before the call and writes only listed ones, so the loop is race free.
void FillFromKnown(const std::vector<cv::Point>& holes, const cv::Mat& known, const cv::Mat& labels,
                   const std::vector<float>& background_z, int radius_px, float band, bool ignore_depth, cv::Mat* bgr,
                   cv::Mat* depth_m, std::vector<uint8_t>* filled) {
  const int width = known.cols;
  const int height = known.rows;
  cv::parallel_for_(cv::Range(0, static_cast<int>(holes.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const cv::Point p = holes[i];
      const float z_back = background_z[labels.at<int>(p)];
      const int x0 = std::max(0, p.x - radius_px), x1 = std::min(width - 1, p.x + radius_px);
      const int y0 = std::max(0, p.y - radius_px), y1 = std::min(height - 1, p.y + radius_px);
      float sum_w = 0, sum_z = 0, sum_b = 0, sum_g = 0, sum_r = 0;
      for (int y = y0; y <= y1; ++y) {
        const uint8_t* k = known.ptr<uint8_t>(y);
        const float* z = depth_m->ptr<float>(y);
        const cv::Vec3b* colour = bgr->ptr<cv::Vec3b>(y);
        for (int x = x0; x <= x1; ++x) {
          if (k[x] == 0) continue;
          float w_z = 1.0f;
          if (!ignore_depth && z_back > 0) w_z = SoftZWeight(std::max(0.0f, (z_back - z[x]) / z_back), band);
          if (w_z <= 0) continue;
          const float d2 = static_cast<float>((x - p.x) * (x - p.x) + (y - p.y) * (y - p.y));
          const float w = w_z / (1.0f + d2);
          sum_w += w;
          sum_z += w * z[x];
          sum_b += w * colour[x][0];
          sum_g += w * colour[x][1];
          sum_r += w * colour[x][2];
        }
      }
      if (sum_w <= 0) continue;
      const float inv = 1.0f / sum_w;
      bgr->at<cv::Vec3b>(p) = cv::Vec3b(cv::saturate_cast<uint8_t>(sum_b * inv), cv::saturate_cast<uint8_t>(sum_g * inv),
                                        cv::saturate_cast<uint8_t>(sum_r * inv));
      depth_m->at<float>(p) = sum_z * inv;
      (*filled)[i] = 1;
    }
  });
}

// Labels the holes' connected parts (8-connected) and returns, per label, the depth of the
// background around it: the 90th percentile of the depths of the covered pixels bordering it
// (a percentile, so one wild depth does not decide). 0 where a part borders nothing known.
// Visits only the hole pixels' neighbours.
std::vector<float> BackgroundDepths(const std::vector<cv::Point>& holes, const cv::Mat& coverage,
                                    const cv::Mat& depth_m, cv::Mat* labels) {
  const int count = cv::connectedComponents(coverage == 0, *labels, 8, CV_32S);
  std::vector<std::vector<float>> border(count);
  for (const cv::Point& p : holes) {
    const int label = labels->at<int>(p);
    const cv::Point neighbours[4] = {{p.x - 1, p.y}, {p.x + 1, p.y}, {p.x, p.y - 1}, {p.x, p.y + 1}};
    for (const cv::Point& n : neighbours) {
      if (n.x < 0 || n.y < 0 || n.x >= coverage.cols || n.y >= coverage.rows) continue;
      if (coverage.at<uint8_t>(n) == 0) continue;
      const float z = depth_m.at<float>(n);
      if (z > 0) border[label].push_back(z);
    }
  }
  std::vector<float> background(count, 0.0f);
  for (int label = 1; label < count; ++label) {
    std::vector<float>& depths = border[label];
    if (depths.empty()) continue;
    auto at = depths.begin() + static_cast<std::ptrdiff_t>(0.9 * static_cast<double>(depths.size() - 1));
    std::nth_element(depths.begin(), at, depths.end());
    background[label] = *at;
  }
  return background;
}

}  // namespace

HoleFillReport FillHoles(const cv::Mat& coverage, int radius_px, float soft_z_band, cv::Mat* bgr, cv::Mat* depth_m) {
  PX_CHECK(bgr != nullptr && depth_m != nullptr) << "FillHoles needs outputs";
  PX_CHECK(coverage.type() == CV_8U && bgr->type() == CV_8UC3 && depth_m->type() == CV_32F)
      << "FillHoles types " << coverage.type() << " " << bgr->type() << " " << depth_m->type();
  PX_CHECK(coverage.size() == bgr->size() && coverage.size() == depth_m->size()) << "FillHoles sizes differ";
  HoleFillReport report;
  radius_px = std::max(1, radius_px);

  // Hole pixels as a list, so a covered frame costs one scan.
  std::vector<cv::Point> holes;
  for (int y = 0; y < coverage.rows; ++y) {
    const uint8_t* row = coverage.ptr<uint8_t>(y);
    for (int x = 0; x < coverage.cols; ++x) {
      if (row[x] == 0) holes.emplace_back(x, y);
    }
  }
  report.hole_pixels = static_cast<int>(holes.size());
  if (holes.empty() || static_cast<size_t>(report.hole_pixels) == coverage.total()) return report;

  // Ring by ring from the covered pixels inwards: each pass fills the pixels within the radius of
  // known background, then they count as known. The first ring is the paper's small-hole fill;
  // the later rings carry the background on into larger holes. Hole pixels bordered only by
  // foreground wait until background reaches them; if a ring fills nothing (a hole surrounded by
  // foreground alone), depth is ignored for the next.
  cv::Mat labels;
  const std::vector<float> background_z = BackgroundDepths(holes, coverage, *depth_m, &labels);
  cv::Mat known = coverage.clone();
  std::vector<uint8_t> filled(holes.size(), 0);
  bool ignore_depth = false;
  for (int ring = 0; !holes.empty(); ++ring) {
    std::fill(filled.begin(), filled.end(), 0);
    FillFromKnown(holes, known, labels, background_z, radius_px, soft_z_band, ignore_depth, bgr, depth_m, &filled);
    std::vector<cv::Point> remaining;
    int newly_filled = 0;
    for (size_t i = 0; i < holes.size(); ++i) {
      if (filled[i]) {
        known.at<uint8_t>(holes[i]) = 255;
        ++newly_filled;
      } else {
        remaining.push_back(holes[i]);
      }
    }
    if (ring == 0) {
      report.filled_from_far += newly_filled;
    } else {
      report.propagated += newly_filled;
    }
    PX_CHECK(newly_filled > 0 || !ignore_depth) << "hole filling stalled with " << remaining.size() << " pixels left";
    ignore_depth = newly_filled == 0;
    holes = std::move(remaining);
    filled.resize(holes.size());
  }
  return report;
}

}  // namespace px::render
