#include "pipeline/direct/view_morph.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <vector>

#include "pipeline/core/stage_clock.h"

namespace px::direct {

namespace {

// Gradient magnitude (Sobel, grey levels per pixel) a pixel needs to offer its flow to RANSAC:
// flow in flat regions is interpolated, not measured.
constexpr float kTexturedGradient = 8.0f;
// Flow samples offered to RANSAC at most (spread on a grid).
constexpr int kMaxFundamentalSamples = 4000;

cv::Mat Grey(const cv::Mat& bgr) {
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

// 255 where flow `ab` is undone by `ba` at its destination within `tolerance` pixels.
cv::Mat Consistent(const cv::Mat& ab, const cv::Mat& ba, double tolerance) {
  cv::Mat map(ab.size(), CV_32FC2);
  for (int y = 0; y < ab.rows; ++y) {
    const cv::Vec2f* f = ab.ptr<cv::Vec2f>(y);
    cv::Vec2f* m = map.ptr<cv::Vec2f>(y);
    for (int x = 0; x < ab.cols; ++x) m[x] = cv::Vec2f(x + f[x][0], y + f[x][1]);
  }
  cv::Mat back;
  cv::remap(ba, back, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(1e6, 1e6));
  cv::Mat seen(ab.size(), CV_8U);
  const float tol2 = static_cast<float>(tolerance * tolerance);
  for (int y = 0; y < ab.rows; ++y) {
    const cv::Vec2f* f = ab.ptr<cv::Vec2f>(y);
    const cv::Vec2f* g = back.ptr<cv::Vec2f>(y);
    uint8_t* s = seen.ptr<uint8_t>(y);
    for (int x = 0; x < ab.cols; ++x) {
      const float dx = f[x][0] + g[x][0], dy = f[x][1] + g[x][1];
      s[x] = dx * dx + dy * dy < tol2 ? 255 : 0;
    }
  }
  return seen;
}

// Signed distance (pixels) of q from the epipolar line F * p, and the line's unit normal.
inline double EpipolarDistance(
    const cv::Matx33d& f, double px, double py, double qx, double qy, double* nx, double* ny) {
  const double a = f(0, 0) * px + f(0, 1) * py + f(0, 2);
  const double b = f(1, 0) * px + f(1, 1) * py + f(1, 2);
  const double c = f(2, 0) * px + f(2, 1) * py + f(2, 2);
  const double norm = std::hypot(a, b);
  if (norm < 1e-12) {
    *nx = *ny = 0;
    return 0;
  }
  *nx = a / norm;
  *ny = b / norm;
  return (a * qx + b * qy + c) / norm;
}

// Pulls each flow vector towards its epipolar line with weight exp(-e^2 / 2 sigma^2).
void SoftEpipolar(const cv::Matx33d& f, double sigma, cv::Mat* flow) {
  const double inv = 1.0 / (2 * sigma * sigma);
  for (int y = 0; y < flow->rows; ++y) {
    cv::Vec2f* row = flow->ptr<cv::Vec2f>(y);
    for (int x = 0; x < flow->cols; ++x) {
      double nx, ny;
      const double e = EpipolarDistance(f, x, y, x + row[x][0], y + row[x][1], &nx, &ny);
      const double w = std::exp(-e * e * inv);
      row[x][0] -= static_cast<float>(w * e * nx);
      row[x][1] -= static_cast<float>(w * e * ny);
    }
  }
}

// Fills the pixels of `flow` where `known` is 0 from known neighbours, ring by ring (pixels
// still unknown after 64 rings keep zero flow).
void FillFlowHoles(cv::Mat* flow, cv::Mat* known) {
  std::vector<cv::Point> holes;
  for (int y = 0; y < known->rows; ++y) {
    const uint8_t* k = known->ptr<uint8_t>(y);
    for (int x = 0; x < known->cols; ++x) {
      if (!k[x]) holes.emplace_back(x, y);
    }
  }
  std::vector<cv::Point> filled, remaining;
  std::vector<cv::Vec2f> values;
  for (int pass = 0; pass < 64 && !holes.empty(); ++pass) {
    filled.clear();
    values.clear();
    remaining.clear();
    for (const cv::Point& p : holes) {
      cv::Vec2f sum(0, 0);
      int n = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        const int yy = p.y + dy;
        if (yy < 0 || yy >= flow->rows) continue;
        const uint8_t* kk = known->ptr<uint8_t>(yy);
        const cv::Vec2f* ff = flow->ptr<cv::Vec2f>(yy);
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = p.x + dx;
          if (xx < 0 || xx >= flow->cols || !kk[xx]) continue;
          sum += ff[xx];
          ++n;
        }
      }
      if (n > 0) {
        filled.push_back(p);
        values.push_back(sum / n);
      } else {
        remaining.push_back(p);
      }
    }
    if (filled.empty()) break;
    for (size_t i = 0; i < filled.size(); ++i) {
      flow->at<cv::Vec2f>(filled[i]) = values[i];
      known->at<uint8_t>(filled[i]) = 255;
    }
    holes.swap(remaining);
  }
}

}  // namespace

Status MorphOptions::Validate() const {
  if (working_width_px < 64 || working_width_px > 4096) {
    return InvalidArgumentError("morph.working_width_px: " + std::to_string(working_width_px) +
                                " is outside [64, 4096]");
  }
  if (!(epipolar_sigma_px > 0 && epipolar_sigma_px <= 50)) {
    return InvalidArgumentError("morph.epipolar_sigma_px: " + std::to_string(epipolar_sigma_px) +
                                " is outside (0, 50]");
  }
  if (!(consistency_px > 0 && consistency_px <= 20)) {
    return InvalidArgumentError("morph.consistency_px: " + std::to_string(consistency_px) + " is outside (0, 20]");
  }
  return OkStatus();
}

StatusOr<std::unique_ptr<ViewMorph>> ViewMorph::Create(const cv::Mat& a,
                                                       const cv::Mat& b,
                                                       const MorphOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  if (a.empty() || b.empty() || a.type() != CV_8UC3 || b.type() != CV_8UC3 || a.size() != b.size()) {
    return InvalidArgumentError("morph: views must be CV_8UC3 of one size, got " + std::to_string(a.cols) + "x" +
                                std::to_string(a.rows) + " type " + std::to_string(a.type()) + " and " +
                                std::to_string(b.cols) + "x" + std::to_string(b.rows) + " type " +
                                std::to_string(b.type()));
  }
  if (a.cols < 16 || a.rows < 16) {
    return InvalidArgumentError("morph: views of " + std::to_string(a.cols) + "x" + std::to_string(a.rows) +
                                " are too small, want at least 16x16");
  }
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<ViewMorph> morph(new ViewMorph());
  morph->a_ = a;
  morph->b_ = b;
  MorphReport& report = morph->report_;

  const double scale = std::min(1.0, static_cast<double>(options.working_width_px) / a.cols);
  cv::Mat grey_a = Grey(a), grey_b = Grey(b);
  cv::Mat small_a = grey_a, small_b = grey_b;
  if (scale < 1.0) {
    cv::resize(grey_a, small_a, cv::Size(), scale, scale, cv::INTER_AREA);
    cv::resize(grey_b, small_b, cv::Size(), scale, scale, cv::INTER_AREA);
  }
  cv::Ptr<cv::DISOpticalFlow> dis = cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_MEDIUM);
  cv::Mat ab, ba;
  dis->calc(small_a, small_b, ab);
  dis->calc(small_b, small_a, ba);
  const double tolerance = std::max(0.5, options.consistency_px * scale);
  cv::Mat seen_ab = Consistent(ab, ba, tolerance);
  cv::Mat seen_ba = Consistent(ba, ab, tolerance);
  report.consistent_fraction = static_cast<double>(cv::countNonZero(seen_ab)) / static_cast<double>(seen_ab.total());

  // Fundamental matrix from textured, consistent flow samples.
  cv::Mat gx, gy, gradient;
  cv::Sobel(small_a, gx, CV_32F, 1, 0, 3, 0.125);
  cv::Sobel(small_a, gy, CV_32F, 0, 1, 3, 0.125);
  cv::magnitude(gx, gy, gradient);
  std::vector<cv::Point2f> from, to;
  const int stride = std::max(2, static_cast<int>(std::sqrt(static_cast<double>(ab.total()) / kMaxFundamentalSamples)));
  for (int y = stride / 2; y < ab.rows; y += stride) {
    for (int x = stride / 2; x < ab.cols; x += stride) {
      if (!seen_ab.at<uint8_t>(y, x) || gradient.at<float>(y, x) < kTexturedGradient) continue;
      const cv::Vec2f f = ab.at<cv::Vec2f>(y, x);
      from.emplace_back(static_cast<float>(x), static_cast<float>(y));
      to.emplace_back(x + f[0], y + f[1]);
    }
  }
  report.fundamental_samples = static_cast<int>(from.size());
  const cv::Mat textured = gradient >= kTexturedGradient;
  const int textured_pixels = cv::countNonZero(textured);
  report.textured_fraction = static_cast<double>(textured_pixels) / static_cast<double>(textured.total());
  report.textured_consistent =
      textured_pixels == 0 ? 0 : cv::countNonZero(textured & seen_ab) / static_cast<double>(textured_pixels);
  const double sigma = options.epipolar_sigma_px * scale;
  if (from.size() >= 30) {
    std::vector<uint8_t> inliers;
    cv::Mat f;
    try {
      f = cv::findFundamentalMat(from, to, cv::FM_RANSAC, std::max(0.5, 1.5 * scale), 0.999, inliers);
    } catch (const cv::Exception&) {
      f.release();  // degenerate samples: morph along the flow as it is
    }
    if (f.rows == 3 && f.cols == 3) {
      const int count = static_cast<int>(std::count(inliers.begin(), inliers.end(), 1));
      report.fundamental_inliers = static_cast<double>(count) / static_cast<double>(from.size());
      if (report.fundamental_inliers >= 0.3) {
        report.epipolar = true;
        const cv::Matx33d fab(f);
        std::vector<double> distances;
        int moving = 0;
        for (size_t i = 0; i < from.size(); ++i) {
          double nx, ny;
          const double e = std::abs(EpipolarDistance(fab, from[i].x, from[i].y, to[i].x, to[i].y, &nx, &ny));
          distances.push_back(e / scale);
          moving += e > 3 * sigma ? 1 : 0;
        }
        std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
        report.median_epipolar_px = distances[distances.size() / 2];
        report.moving_fraction = static_cast<double>(moving) / static_cast<double>(from.size());
        SoftEpipolar(fab, sigma, &ab);
        SoftEpipolar(fab.t(), sigma, &ba);
      }
    }
  }

  // Full-size flows and visibility.
  if (scale < 1.0) {
    cv::resize(ab, morph->flow_ab_, a.size(), 0, 0, cv::INTER_LINEAR);
    cv::resize(ba, morph->flow_ba_, a.size(), 0, 0, cv::INTER_LINEAR);
    morph->flow_ab_ *= 1.0 / scale;
    morph->flow_ba_ *= 1.0 / scale;
    cv::resize(seen_ab, morph->seen_ab_, a.size(), 0, 0, cv::INTER_NEAREST);
    cv::resize(seen_ba, morph->seen_ba_, a.size(), 0, 0, cv::INTER_NEAREST);
  } else {
    morph->flow_ab_ = ab;
    morph->flow_ba_ = ba;
    morph->seen_ab_ = seen_ab;
    morph->seen_ba_ = seen_ba;
  }

  // How well the flow explains b from a, against not warping at all.
  cv::Mat map(a.size(), CV_32FC2);
  for (int y = 0; y < a.rows; ++y) {
    const cv::Vec2f* f = morph->flow_ab_.ptr<cv::Vec2f>(y);
    cv::Vec2f* m = map.ptr<cv::Vec2f>(y);
    for (int x = 0; x < a.cols; ++x) m[x] = cv::Vec2f(x + f[x][0], y + f[x][1]);
  }
  cv::Mat warped;
  cv::remap(grey_b, warped, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  cv::Mat diff_unwarped, diff_warped;
  cv::absdiff(grey_a, grey_b, diff_unwarped);
  cv::absdiff(grey_a, warped, diff_warped);
  report.mean_abs_diff_unwarped = cv::mean(diff_unwarped)[0];
  report.mean_abs_diff_warped = cv::mean(diff_warped, morph->seen_ab_)[0];
  report.ms = MsSince(start);
  return morph;
}

cv::Point2d ViewMorph::TrackFromA(const cv::Point2d& pixel_in_a, double t) const {
  const int x = std::clamp(static_cast<int>(std::lround(pixel_in_a.x)), 0, flow_ab_.cols - 1);
  const int y = std::clamp(static_cast<int>(std::lround(pixel_in_a.y)), 0, flow_ab_.rows - 1);
  const cv::Vec2f f = flow_ab_.at<cv::Vec2f>(y, x);
  return {pixel_in_a.x + t * f[0], pixel_in_a.y + t * f[1]};
}

cv::Mat ViewMorph::FrameAt(double t) const {
  t = std::clamp(t, 0.0, 1.0);
  const int width = a_.cols, height = a_.rows;
  // Flow at time t, a to b, splatted from both ends; a pixel both views see wins a clash.
  cv::Mat flow_t(height, width, CV_32FC2, cv::Scalar(0, 0));
  cv::Mat priority(height, width, CV_8U, cv::Scalar(0));
  const auto splat = [&](const cv::Mat& flow, const cv::Mat& seen, double travel, double sign) {
    for (int y = 0; y < height; ++y) {
      const cv::Vec2f* f = flow.ptr<cv::Vec2f>(y);
      const uint8_t* s = seen.ptr<uint8_t>(y);
      for (int x = 0; x < width; ++x) {
        const int tx = static_cast<int>(std::lround(x + travel * f[x][0]));
        const int ty = static_cast<int>(std::lround(y + travel * f[x][1]));
        if (tx < 0 || ty < 0 || tx >= width || ty >= height) continue;
        const uint8_t p = s[x] ? 2 : 1;
        uint8_t& existing = priority.at<uint8_t>(ty, tx);
        if (p <= existing) continue;
        existing = p;
        flow_t.at<cv::Vec2f>(ty, tx) = static_cast<float>(sign) * f[x];
      }
    }
  };
  splat(flow_ab_, seen_ab_, t, 1.0);
  splat(flow_ba_, seen_ba_, 1.0 - t, -1.0);
  cv::Mat known = priority > 0;
  FillFlowHoles(&flow_t, &known);

  cv::Mat map_a(height, width, CV_32FC2), map_b(height, width, CV_32FC2);
  for (int y = 0; y < height; ++y) {
    const cv::Vec2f* f = flow_t.ptr<cv::Vec2f>(y);
    cv::Vec2f* ma = map_a.ptr<cv::Vec2f>(y);
    cv::Vec2f* mb = map_b.ptr<cv::Vec2f>(y);
    for (int x = 0; x < width; ++x) {
      ma[x] = cv::Vec2f(static_cast<float>(x - t * f[x][0]), static_cast<float>(y - t * f[x][1]));
      mb[x] = cv::Vec2f(static_cast<float>(x + (1 - t) * f[x][0]), static_cast<float>(y + (1 - t) * f[x][1]));
    }
  }
  cv::Mat from_a, from_b, seen_a, seen_b;
  cv::remap(a_, from_a, map_a, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  cv::remap(b_, from_b, map_b, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  cv::remap(seen_ab_, seen_a, map_a, cv::noArray(), cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::remap(seen_ba_, seen_b, map_b, cv::noArray(), cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::Mat frame(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    const cv::Vec3b* pa = from_a.ptr<cv::Vec3b>(y);
    const cv::Vec3b* pb = from_b.ptr<cv::Vec3b>(y);
    const uint8_t* va = seen_a.ptr<uint8_t>(y);
    const uint8_t* vb = seen_b.ptr<uint8_t>(y);
    cv::Vec3b* out = frame.ptr<cv::Vec3b>(y);
    for (int x = 0; x < width; ++x) {
      // A view that does not see the pixel (occluded there) only fills in for the other.
      const double wa = (1 - t) * (va[x] ? 1.0 : 0.05);
      const double wb = t * (vb[x] ? 1.0 : 0.05);
      const double sum = wa + wb;
      const double ka = sum > 0 ? wa / sum : 1.0 - t;
      for (int c = 0; c < 3; ++c) out[x][c] = cv::saturate_cast<uint8_t>(ka * pa[x][c] + (1 - ka) * pb[x][c]);
    }
  }
  return frame;
}

}  // namespace px::direct
