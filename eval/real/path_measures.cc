#include "eval/real/path_measures.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "eval/render/image_metrics.h"

namespace px::eval {
namespace {

// The world point of pixel (x, y) of `camera` at depth z.
Eigen::Vector3d WorldPoint(const VirtualCamera& camera, double x, double y, double z) {
  const CameraModel& k = camera.camera;
  const Eigen::Vector3d in_camera(z * (x - k.cx) / k.fx, z * (y - k.cy) / k.fy, z);
  return camera.cam_from_world.Inverse() * in_camera;
}

// Whether the sources that see world point `point` show a surface there where the frame shows
// `shown` (BGR): true when at least one does, seeing it at the point's depth in a colour more
// than `levels` from `shown`, and none sees past it or sees `shown` itself there (a real gap that
// the source's depth smooths over still shows the far colour in its image).
bool SourcesShowSurface(const Eigen::Vector3d& point,
                        const cv::Vec3b& shown,
                        const std::vector<const View*>& sources,
                        const std::vector<const DepthMap*>& depths,
                        double far_fraction,
                        int levels) {
  int surface = 0;
  for (size_t i = 0; i < sources.size(); ++i) {
    const Eigen::Vector3d in_source = sources[i]->cam_from_world * point;
    Eigen::Vector2d pixel;
    if (!(in_source.z() > 0) || !sources[i]->camera.Project(in_source, &pixel)) continue;
    const int u = static_cast<int>(std::lround(pixel.x())), v = static_cast<int>(std::lround(pixel.y()));
    const cv::Mat& map = depths[i]->depth_m;
    if (u < 0 || v < 0 || u >= map.cols || v >= map.rows || u >= sources[i]->image.cols ||
        v >= sources[i]->image.rows) {
      continue;
    }
    const double seen = map.at<float>(v, u);
    if (!(seen > 0)) continue;
    if (seen > (1 + far_fraction) * in_source.z()) return false;  // this source sees through: a real gap
    if (seen < (1 - far_fraction) * in_source.z()) continue;      // hidden there: no say
    const cv::Vec3b colour = sources[i]->image.at<cv::Vec3b>(v, u);
    int apart = 0;
    for (int c = 0; c < 3; ++c) apart = std::max(apart, std::abs(colour[c] - shown[c]));
    if (apart <= levels) return false;  // the source's image shows what the frame shows
    ++surface;
  }
  return surface > 0;
}

}  // namespace

double TornFraction(const FrameRender& frame,
                    const VirtualCamera& camera,
                    const std::vector<View>& views,
                    const std::vector<DepthMap>& depth,
                    const TearOptions& options,
                    cv::Mat* map) {
  const cv::Mat& z = frame.depth_m;
  cv::Mat torn = cv::Mat::zeros(z.size(), CV_8U);
  std::vector<const View*> sources;
  std::vector<const DepthMap*> source_depths;
  for (const ViewId id : frame.sources) {
    for (size_t i = 0; i < views.size() && i < depth.size(); ++i) {
      if (views[i].id == id && static_cast<int>(sources.size()) < options.max_sources) {
        sources.push_back(&views[i]);
        source_depths.push_back(&depth[i]);
      }
    }
  }
  if (z.empty() || sources.empty()) {
    if (map != nullptr) *map = torn;
    return 0;
  }
  const double f = options.far_fraction;
  constexpr std::array<std::array<int, 2>, 4> kDirections = {{{1, 0}, {0, 1}, {1, 1}, {1, -1}}};
  cv::parallel_for_(cv::Range(0, z.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      for (int x = 0; x < z.cols; ++x) {
        const float here = z.at<float>(y, x);
        if (!(here > 0)) continue;
        const auto near_side = [&](int sx, int sy, float* side) {
          if (sx < 0 || sy < 0 || sx >= z.cols || sy >= z.rows) return false;
          *side = z.at<float>(sy, sx);
          return *side > 0 && here > (1 + f) * *side;
        };
        bool is_torn = false;
        for (const auto& d : kDirections) {
          for (int a = 1; a <= options.max_gap_px && !is_torn; ++a) {
            float za = 0;
            if (!near_side(x - a * d[0], y - a * d[1], &za)) continue;
            for (int b = 1; a + b - 1 <= options.max_gap_px && !is_torn; ++b) {
              float zb = 0;
              if (!near_side(x + b * d[0], y + b * d[1], &zb)) continue;
              if (std::abs(za - zb) > f * std::min(za, zb)) continue;  // not one surface
              // The near surface across the gap, linear between its sides.
              const double across = za + (zb - za) * static_cast<double>(a) / (a + b);
              is_torn = SourcesShowSurface(WorldPoint(camera, x, y, across),
                                           frame.bgr.at<cv::Vec3b>(y, x),
                                           sources,
                                           source_depths,
                                           f,
                                           options.colour_levels);
            }
          }
          if (is_torn) break;
        }
        if (is_torn) torn.at<uint8_t>(y, x) = 255;
      }
    }
  });
  if (map != nullptr) *map = torn;
  return static_cast<double>(cv::countNonZero(torn)) / static_cast<double>(torn.total());
}

double FlickerFraction(const cv::Mat& previous_bgr,
                       const VirtualCamera& previous_camera,
                       const FrameRender& current,
                       const VirtualCamera& camera,
                       int threshold,
                       cv::Mat* map) {
  const cv::Mat& z = current.depth_m;
  cv::Mat map_x(z.size(), CV_32F, cv::Scalar(-1)), map_y(z.size(), CV_32F, cv::Scalar(-1));
  cv::Mat inside = cv::Mat::zeros(z.size(), CV_8U);
  for (int y = 0; y < z.rows; ++y) {
    for (int x = 0; x < z.cols; ++x) {
      const float depth = z.at<float>(y, x);
      if (!(depth > 0)) continue;
      const Eigen::Vector3d in_previous = previous_camera.cam_from_world * WorldPoint(camera, x, y, depth);
      Eigen::Vector2d pixel;
      if (!(in_previous.z() > 0) || !previous_camera.camera.Project(in_previous, &pixel)) continue;
      if (pixel.x() < 0 || pixel.y() < 0 || pixel.x() > previous_bgr.cols - 1 || pixel.y() > previous_bgr.rows - 1)
        continue;
      map_x.at<float>(y, x) = static_cast<float>(pixel.x());
      map_y.at<float>(y, x) = static_cast<float>(pixel.y());
      inside.at<uint8_t>(y, x) = 255;
    }
  }
  cv::Mat reprojected, difference;
  cv::remap(previous_bgr, reprojected, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  cv::absdiff(reprojected, current.bgr, difference);
  std::vector<cv::Mat> channels;
  cv::split(difference, channels);
  cv::Mat largest = cv::max(cv::max(channels[0], channels[1]), channels[2]);
  const cv::Mat changing = MaskRegions((largest > threshold) & inside);
  if (map != nullptr) *map = changing;
  const int counted = cv::countNonZero(inside);
  return counted > 0 ? static_cast<double>(cv::countNonZero(changing)) / counted : 0.0;
}

}  // namespace px::eval
