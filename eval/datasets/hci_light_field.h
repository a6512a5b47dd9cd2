// The HCI 4D light field benchmark layout (../shared/data/hci_4dlf_antinous, SOURCES.md 1): a
// 9x9 grid of 512x512 views on a plane with parallel optical axes and principal points shifted
// so that the focus plane has zero disparity, plus the centre view's ground-truth disparity.
//
// Geometry, from parameters.cfg: f_px = focal_length_mm / sensor_size_mm * width; baseline B in
// metres; offset = f_px * B / focus_distance (the cfg's `offset`). Camera (r, c) sits at
// ((c - 4) B, (r - 4) B, 0) in the centre camera's frame (x right, y down) with principal point
// shifted by offset * (c - 4, r - 4). Disparity d (pixels per grid step) and depth z relate by
// d = f_px B / z - offset, and I_centre(x, y) = I_(r,c)(x - d (c - 4), y - d (r - 4)).
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/core/view.h"

namespace px::eval {

struct HciLightField {
  std::string scene;  // "antinous"
  int rows = 0;       // grid size (9 x 9)
  int cols = 0;
  double focal_px = 0;
  double baseline_m = 0;  // between adjacent grid cameras
  double focus_distance_m = 0;
  double offset_px = 0;  // disparity of infinity is -offset_px
  double disp_min = 0;   // the scene's disparity range (cfg disp_min / disp_max)
  double disp_max = 0;
  // Row-major (index r * cols + c, row 0 = top), id = index, world = the centre camera's frame.
  std::vector<View> views;
  cv::Mat gt_disparity;  // CV_32F of the centre view; empty when the set has none

  int CentreIndex() const { return (rows / 2) * cols + cols / 2; }
  // The camera of view `index` as parameters.cfg gives it: focal length from focal_length_mm and
  // sensor_size_mm, principal point shifted by offset_px per grid step from the centre view.
  CameraModel MetadataCamera(int index, int width, int height) const;
  double DepthFromDisparity(double d) const { return focal_px * baseline_m / (d + offset_px); }
  double DisparityFromDepth(double z) const { return focal_px * baseline_m / z - offset_px; }
  // Ground-truth depth (z, metres) of the centre view from gt_disparity.
  cv::Mat GtDepth() const;
  // The (2 radius + 1)^2 views around the centre, row-major, keeping their ids (a Pop9-like 3x3
  // for radius 1). The centre view is at index (2 radius + 1)^2 / 2 of the result.
  std::vector<View> CentreGrid(int radius) const;
};

// Reads parameters.cfg, input_CamNNN.png and gt_disp_lowres.pfm (optional) from `dir`. Errors
// name the file and the key.
StatusOr<HciLightField> LoadHciLightField(const std::filesystem::path& dir);

}  // namespace px::eval
