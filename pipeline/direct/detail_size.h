// A frame enlarged beyond the capture's detail (a 1080p clip cut from 640x480 views, a portrait
// cut from a landscape photo) holds no more than the capture saw. It is drawn at that detail and
// enlarged (bicubic), which costs 1 / scale^2 of drawing it at the output size; the texels a
// renderer would fetch at the output size are bilinear samples of the same source pixels.
#pragma once

#include <opencv2/core.hpp>

#include "pipeline/core/virtual_camera.h"

namespace px::direct {

// Enlargements at or below this are drawn at the output size (resampling hides them).
inline constexpr double kDrawAtDetailAbove = 1.05;

// `camera` (the output's pinhole) at the capture's detail: its size divided by `output_scale`
// (output pixels per capture pixel), focal lengths and principal point mapped exactly as
// EnlargeToOutput maps the pixels back. `camera` itself when output_scale <= kDrawAtDetailAbove.
VirtualCamera CameraAtDetail(const VirtualCamera& camera, double output_scale);

// `drawn` (CameraAtDetail's size) enlarged to `width` x `height`; `drawn` itself at that size.
cv::Mat EnlargeToOutput(const cv::Mat& drawn, int width, int height);

}  // namespace px::direct
