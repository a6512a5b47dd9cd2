// LLFF forward-facing captures (../shared/data/llff_fern, SOURCES.md 6): images_8/imageNNN.png,
// poses_bounds.npy (one row per image: a 3x5 camera-to-world matrix with columns down, right,
// backwards, translation, and (H, W, f) at full resolution; then near and far depth bounds) and
// COLMAP's sparse/0/cameras.bin (SIMPLE_RADIAL: f, cx, cy, k1 at full resolution). The poses
// are COLMAP's estimate: a reference, not ground truth.
#pragma once

#include <filesystem>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/core/view.h"

namespace px::eval {

struct LlffScene {
  // One per image, id = index; camera scaled to the images' size (distortion: COLMAP's k1);
  // cam_from_world in OpenCV axes (x right, y down, z forward), world = COLMAP's frame (scale
  // arbitrary).
  std::vector<View> views;
  std::vector<double> near_depth;  // poses_bounds near / far bounds per view, world units
  std::vector<double> far_depth;
  double downscale = 1;  // full-resolution width / image width (8 for images_8)
};

// `images` picks the image folder ("images_8"). Errors name the file and the field.
StatusOr<LlffScene> LoadLlffScene(const std::filesystem::path& dir, const std::string& images = "images_8");

}  // namespace px::eval
