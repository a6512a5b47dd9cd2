#include "pipeline/render/depth_of_field.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

namespace px::render {
namespace {

constexpr double kMaxSigmaPx = 32;

// The blur levels L_0..L_J (section 8): 0 = sharp, j = Gaussian sigma 2^(j-1); from level 3 on
// stored at 1 / 2^(j-2) of the size and read back bilinearly.
class BlurStack {
 public:
  BlurStack(const cv::Mat& colour, int levels) : levels_(levels) {
    images_.push_back(colour);
    scales_.push_back(1);
    for (int j = 1; j <= levels; ++j) {
      cv::Mat level;
      if (j <= 2) {
        const double sigma = j == 1 ? 1.0 : 2.0;
        cv::GaussianBlur(colour, level, cv::Size(0, 0), sigma, sigma, cv::BORDER_REPLICATE);
        scales_.push_back(1);
      } else {
        const int scale = 1 << (j - 2);
        cv::Mat small;
        cv::resize(colour,
                   small,
                   cv::Size(std::max(1, colour.cols / scale), std::max(1, colour.rows / scale)),
                   0,
                   0,
                   cv::INTER_AREA);
        cv::GaussianBlur(small, level, cv::Size(0, 0), 2.0, 2.0, cv::BORDER_REPLICATE);
        scales_.push_back(static_cast<float>(colour.cols) / static_cast<float>(small.cols));
      }
      images_.push_back(level);
    }
  }

  int levels() const { return levels_; }

  cv::Vec3f At(int level, int x, int y) const {
    const cv::Mat& image = images_[level];
    if (scales_[level] == 1.0f) return image.at<cv::Vec3f>(y, x);
    const float s = scales_[level];
    const float u = std::clamp((x + 0.5f) / s - 0.5f, 0.0f, static_cast<float>(image.cols - 1));
    const float v = std::clamp((y + 0.5f) / s - 0.5f, 0.0f, static_cast<float>(image.rows - 1));
    const int u0 = std::min(static_cast<int>(u), image.cols - 1), v0 = std::min(static_cast<int>(v), image.rows - 1);
    const int u1 = std::min(u0 + 1, image.cols - 1), v1 = std::min(v0 + 1, image.rows - 1);
    const float fu = u - u0, fv = v - v0;
    return (1 - fv) * ((1 - fu) * image.at<cv::Vec3f>(v0, u0) + fu * image.at<cv::Vec3f>(v0, u1)) +
           fv * ((1 - fu) * image.at<cv::Vec3f>(v1, u0) + fu * image.at<cv::Vec3f>(v1, u1));
  }

  // The frame blurred by a Gaussian of `sigma` px at (x, y), interpolated between levels.
  cv::Vec3f Blurred(float sigma, int x, int y) const {
    if (sigma <= 0 || levels_ == 0) return At(0, x, y);
    if (sigma < 1) return (1 - sigma) * At(0, x, y) + sigma * At(1, x, y);
    const float t = std::min(static_cast<float>(levels_), std::log2(sigma) + 1.0f);
    const int j0 = std::min(static_cast<int>(t), levels_);
    const int j1 = std::min(j0 + 1, levels_);
    const float f = t - j0;
    return (1 - f) * At(j0, x, y) + f * At(j1, x, y);
  }

 private:
  int levels_ = 0;
  std::vector<cv::Mat> images_;
  std::vector<float> scales_;
};

}  // namespace

double CircleOfConfusionPx(double aperture_m, double focus_m, double focal_px, double z_m) {
  if (!(aperture_m > 0) || !(focus_m > 0) || !(z_m > 0)) return 0.0;
  return aperture_m * focal_px * std::abs(1.0 / z_m - 1.0 / focus_m);
}

DepthOfFieldReport ApplyPreviewDepthOfField(
    double aperture_m, double focus_m, double focal_px, const cv::Mat& depth, cv::Mat* colour) {
  DepthOfFieldReport report;
  if (!(aperture_m > 0) || colour->empty()) return report;
  const int width = colour->cols, height = colour->rows;
  // Depths <= 0 (nothing there) count as infinitely far.
  const auto coc = [&](float z) {
    return z > 0 ? CircleOfConfusionPx(aperture_m, focus_m, focal_px, z) : aperture_m * focal_px / focus_m;
  };
  double z_min = std::numeric_limits<double>::infinity(), c_max = 0;
  for (int y = 0; y < height; ++y) {
    const float* z = depth.ptr<float>(y);
    for (int x = 0; x < width; ++x) {
      if (z[x] > 0) z_min = std::min(z_min, static_cast<double>(z[x]));
      c_max = std::max(c_max, coc(z[x]));
    }
  }
  const double sigma_max = std::min(kMaxSigmaPx, c_max / 4);
  if (sigma_max < 0.25) return report;  // blur under a quarter pixel: nothing visible
  int levels = 1;
  while (std::pow(2.0, levels - 1) < sigma_max) ++levels;
  report.levels = levels;
  const BlurStack stack(colour->clone(), levels);

  // Foreground in front of the focus plane, blurred by at least a pixel: integral images of its
  // count and depth give the silhouette correction in constant time per pixel.
  cv::Mat foreground(height, width, CV_32F), foreground_z(height, width, CV_32F);
  for (int y = 0; y < height; ++y) {
    const float* z = depth.ptr<float>(y);
    float* f = foreground.ptr<float>(y);
    float* fz = foreground_z.ptr<float>(y);
    for (int x = 0; x < width; ++x) {
      const bool front = z[x] > 0 && z[x] < focus_m && coc(z[x]) >= 1.0;
      f[x] = front ? 1.0f : 0.0f;
      fz[x] = front ? z[x] : 0.0f;
    }
  }
  cv::Mat count_sum, z_sum;
  cv::integral(foreground, count_sum, CV_64F);
  cv::integral(foreground_z, z_sum, CV_64F);
  const auto box = [&](const cv::Mat& sum, int x, int y, int r, double* area) {
    const int x0 = std::max(0, x - r), x1 = std::min(width, x + r + 1);
    const int y0 = std::max(0, y - r), y1 = std::min(height, y + r + 1);
    *area = static_cast<double>(x1 - x0) * (y1 - y0);
    return sum.at<double>(y1, x1) - sum.at<double>(y0, x1) - sum.at<double>(y1, x0) + sum.at<double>(y0, x0);
  };
  const int reach =
      std::isfinite(z_min) ? static_cast<int>(std::min(kMaxSigmaPx, std::ceil(coc(static_cast<float>(z_min)) / 2))) : 0;
  std::vector<int> corrected(height, 0);
  cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const float* z = depth.ptr<float>(y);
      cv::Vec3f* out = colour->ptr<cv::Vec3f>(y);
      for (int x = 0; x < width; ++x) {
        const float sigma = static_cast<float>(std::min(kMaxSigmaPx, coc(z[x]) / 4));
        cv::Vec3f own = stack.Blurred(sigma, x, y);
        if ((z[x] <= 0 || z[x] >= focus_m) && reach > 0) {
          double area = 0;
          const double n = box(count_sum, x, y, reach, &area);
          if (n > 0.5) {
            const double z_bar = box(z_sum, x, y, reach, &area) / n;
            const double c_bar = coc(static_cast<float>(z_bar));
            const int r = static_cast<int>(std::lround(c_bar / 2));
            const double phi = box(count_sum, x, y, r, &area) / area;
            if (phi > 0) {
              const float sigma_bar = static_cast<float>(std::min(kMaxSigmaPx, c_bar / 4));
              own = static_cast<float>(1 - phi) * own + static_cast<float>(phi) * stack.Blurred(sigma_bar, x, y);
              ++corrected[y];
            }
          }
        }
        out[x] = own;
      }
    }
  });
  for (int c : corrected) report.silhouette_pixels += c;
  return report;
}

std::vector<ApertureViewpoint> ApertureViewpoints(
    const CameraModel& camera, const Rigid3& cam_from_world, double aperture_m, double focus_m, int count) {
  std::vector<ApertureViewpoint> viewpoints;
  constexpr double kGoldenAngle = 2.39996322972865332;
  for (int i = 0; i < count; ++i) {
    const double radius = 0.5 * aperture_m * std::sqrt((i + 0.5) / count);
    const double angle = i * kGoldenAngle;
    const Eigen::Vector3d delta(radius * std::cos(angle), radius * std::sin(angle), 0.0);
    ApertureViewpoint v;
    v.camera = camera;
    v.camera.cx += camera.fx * delta.x() / focus_m;
    v.camera.cy += camera.fy * delta.y() / focus_m;
    // Centre moved by delta in the camera frame: p' = p - delta, so t' = t - delta.
    v.cam_from_world = Rigid3(cam_from_world.rotation, cam_from_world.translation - delta);
    viewpoints.push_back(v);
  }
  return viewpoints;
}

}  // namespace px::render
