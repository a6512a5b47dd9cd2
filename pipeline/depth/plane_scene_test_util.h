// Test-only: scenes of textured fronto-parallel planes rendered exactly into pinhole cameras,
// with their true depth, for checking the plane sweep without the synthetic sensor. Each pixel's
// ray is intersected analytically with every plane and the nearest hit's texture is sampled
// bilinearly, which is the exact plane-induced homography of the texture.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/view.h"
#include "pipeline/depth/superpixels.h"

namespace px::depth::testing {

// Square blocks of block_px as the segments of a cols x rows image (a grey image's statistics).
Superpixels BlockSegments(int cols, int rows, int block_px);

// The plane z = depth_m in the world frame, covering world x in [x0, x1], y in [y0, y1]
// (an infinite plane when the extent is empty). The texture is centred on the extent (or on the
// world z axis for an infinite plane), one texel = metres_per_texel square.
struct TexturedPlane {
  double depth_m = 1.0;
  cv::Rect2d extent_m;  // empty: infinite
  cv::Mat texture;      // CV_8UC3
  double metres_per_texel = 0.002;
};

// Multi-octave coloured noise with features from about 2 to 32 texels, values in about [20, 235].
cv::Mat RandomTexture(cv::Size size, uint64_t seed);

// Renders the planes into a camera (nearest hit wins). Rays that hit nothing are black with depth 0.
cv::Mat RenderPlanes(const CameraModel& camera,
                     const Rigid3& cam_from_world,
                     const std::vector<TexturedPlane>& planes,
                     cv::Mat* depth_m = nullptr);

// One view per pose (view id = index), each rendering `planes`.
std::vector<View> RenderViews(const std::vector<Rigid3>& cams_from_world,
                              const CameraModel& camera,
                              const std::vector<TexturedPlane>& planes,
                              std::vector<cv::Mat>* true_depth_m = nullptr);

// The poses of a rows x cols lattice rig: identity rotations, centres on the z = 0 plane, row 0
// at the top, spaced baseline_m, row-major.
std::vector<Rigid3> GridRigPoses(int rows, int cols, double baseline_m);

// A rows x cols lattice rig (identity rotations, camera centres on the z = 0 plane, row 0 at the
// top, spaced baseline_m), each view rendering `planes`; view id = index, row-major.
std::vector<View> RenderGridRig(int rows,
                                int cols,
                                double baseline_m,
                                const CameraModel& camera,
                                const std::vector<TexturedPlane>& planes,
                                std::vector<cv::Mat>* true_depth_m = nullptr);

}  // namespace px::depth::testing
