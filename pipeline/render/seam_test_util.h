// Test-only: a layered view with one layer (no two-layer band anywhere) from a label image, for
// the seam tests (seam_skirts_test.cc).
#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/layered_depth.h"

namespace px::render::testing {

// Segment s covers the pixels labelled s (CV_32S, the camera's size) with colour colours[s] and
// inverse-depth plane planes[s] = {a, b, c}; layer 1 empty, depth_m 1 and confidence 1 everywhere.
inline LayeredDepthView OneLayerView(const CameraModel& camera,
                                     const cv::Mat& labels,
                                     const std::vector<cv::Vec3b>& colours,
                                     const std::vector<std::array<double, 3>>& planes) {
  LayeredDepthView view;
  view.id = ViewId(0);
  view.camera = camera;
  view.segments.resize(planes.size());
  SegmentLayer& front = view.layers[0];
  front.colour.create(camera.height, camera.width, CV_8UC3);
  front.weight = cv::Mat(camera.height, camera.width, CV_32F, cv::Scalar(1));
  front.segment = labels.clone();
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const int s = labels.at<int32_t>(y, x);
      front.colour.at<cv::Vec3b>(y, x) = colours[s];
      DepthSegment& segment = view.segments[s];
      segment.bbox = segment.num_pixels == 0 ? cv::Rect(x, y, 1, 1) : (segment.bbox | cv::Rect(x, y, 1, 1));
      ++segment.num_pixels;
    }
  }
  for (size_t s = 0; s < planes.size(); ++s) {
    view.segments[s].inv_depth_a = planes[s][0];
    view.segments[s].inv_depth_b = planes[s][1];
    view.segments[s].inv_depth_c = planes[s][2];
    view.segments[s].confidence = 1;
  }
  SegmentLayer& back = view.layers[1];
  back.colour = cv::Mat::zeros(camera.height, camera.width, CV_8UC3);
  back.weight = cv::Mat::zeros(camera.height, camera.width, CV_32F);
  back.segment = cv::Mat(camera.height, camera.width, CV_32S, cv::Scalar(SegmentLayer::kNoSegment));
  view.depth_m = cv::Mat(camera.height, camera.width, CV_32F, cv::Scalar(1));
  view.confidence = cv::Mat(camera.height, camera.width, CV_32F, cv::Scalar(1));
  return view;
}

}  // namespace px::render::testing
