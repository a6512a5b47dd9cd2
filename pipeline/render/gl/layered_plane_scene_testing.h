// Test-only: the analytic two-plane scene of pipeline/render/plane_scene_testing.h as the
// renderer's input, exactly: per view two segments (the background plane and the foreground
// rectangle, both fronto-parallel), layer 0 the visible one with weight 1, layer 1 empty. With
// `tile_px` > 0 each plane is cut into tile_px x tile_px segments, as many as a real depth stage
// makes (for benchmarks: one 480x320 view in 16 px tiles has ~600 segments).
#pragma once

#include <opencv2/imgproc.hpp>
#include <vector>

#include "pipeline/render/gl/gl_scene_renderer.h"
#include "pipeline/render/plane_scene_testing.h"

namespace px::render::gl::testing {

inline std::vector<PosedLayeredView> LayeredPlaneScene(const render::testing::PlaneScene& scene,
                                                       int rows,
                                                       int cols,
                                                       double baseline_m,
                                                       const CameraModel& camera,
                                                       int tile_px = 0) {
  std::vector<View> views;
  std::vector<DepthMap> depths;
  render::testing::MakeLatticeViews(scene, rows, cols, baseline_m, camera, &views, &depths);
  std::vector<PosedLayeredView> posed;
  for (size_t v = 0; v < views.size(); ++v) {
    PosedLayeredView out;
    LayeredDepthView& d = out.depth;
    d.id = views[v].id;
    d.camera = camera;
    out.cam_from_world = views[v].cam_from_world;
    const int w = camera.width, h = camera.height;
    d.layers[0].colour = views[v].image.clone();
    d.layers[0].weight = cv::Mat(h, w, CV_32F, cv::Scalar(0));
    d.layers[0].segment = cv::Mat(h, w, CV_32S, cv::Scalar(SegmentLayer::kNoSegment));
    d.layers[1].colour = cv::Mat(h, w, CV_8UC3, cv::Scalar::all(0));
    d.layers[1].weight = cv::Mat(h, w, CV_32F, cv::Scalar(0));
    d.layers[1].segment = cv::Mat(h, w, CV_32S, cv::Scalar(SegmentLayer::kNoSegment));
    d.depth_m = depths[v].depth_m.clone();
    d.confidence = depths[v].confidence.clone();
    const int tiles_x = tile_px > 0 ? (w + tile_px - 1) / tile_px : 1;
    const int tiles_y = tile_px > 0 ? (h + tile_px - 1) / tile_px : 1;
    const int num_segments = 2 * tiles_x * tiles_y;
    d.segments.resize(num_segments);
    for (int s = 0; s < num_segments; ++s) {
      d.segments[s].inv_depth_c = 1.0 / (s % 2 == 1 ? scene.foreground_z : scene.background_z);
    }
    std::vector<std::vector<cv::Point>> pixels(num_segments);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const float z = d.depth_m.at<float>(y, x);
        if (z <= 0) continue;
        const int tile = tile_px > 0 ? (y / tile_px) * tiles_x + x / tile_px : 0;
        const int s = 2 * tile + (std::abs(z - scene.foreground_z) < 1e-4 ? 1 : 0);
        d.layers[0].weight.at<float>(y, x) = 1;
        d.layers[0].segment.at<int32_t>(y, x) = s;
        pixels[s].emplace_back(x, y);
      }
    }
    for (int s = 0; s < num_segments; ++s) {
      d.segments[s].confidence = 1;
      d.segments[s].num_pixels = static_cast<int32_t>(pixels[s].size());
      d.segments[s].bbox = pixels[s].empty() ? cv::Rect() : cv::boundingRect(pixels[s]);
    }
    posed.push_back(std::move(out));
  }
  return posed;
}

}  // namespace px::render::gl::testing
