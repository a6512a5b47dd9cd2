// Colour-effect layers (paper 6.1 "Color effects"; ALGORITHM.md section 7): saturation or brightness
// applied inside a 3D box of the world with a Gaussian falloff outside it (or to the complement),
// composited over the rendered frame in the order given.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/virtual_camera.h"

namespace px::render {

// The effect's strength in [0, 1] at a world point: 1 inside the box, exp(-d^2 / (2 falloff^2)) at
// distance d outside it; 1 minus that when inverted.
double EffectStrength(const ColorEffect& effect, const Eigen::Vector3d& point_in_world);

// Applies `effects` in order to `colour` (CV_32FC3, 0..255, not clamped), each pixel's world point
// taken from `depth` (CV_32F, z in the camera; pixels with z <= 0 count as infinitely far).
void ApplyColorEffects(const std::vector<ColorEffect>& effects,
                       const CameraModel& camera,
                       const Rigid3& cam_from_world,
                       const cv::Mat& depth,
                       cv::Mat* colour);

}  // namespace px::render
