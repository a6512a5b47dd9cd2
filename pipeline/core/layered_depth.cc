#include "pipeline/core/layered_depth.h"

#include <cmath>
#include <cstdio>
#include <string>

namespace px {
namespace {

std::string Where(const LayeredDepthView& view, int layer) {
  return "layered depth of view " + std::to_string(view.id.value) +
         (layer >= 0 ? ", layer " + std::to_string(layer) : "");
}

std::string Number(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", value);
  return text;
}

std::string Pixel(int x, int y) { return "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ")"; }

Status CheckImage(const cv::Mat& image, int type, const CameraModel& camera, const std::string& what) {
  if (image.type() != type || image.cols != camera.width || image.rows != camera.height) {
    return InvalidArgumentError(what + ": got " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                                " of type " + std::to_string(image.type()) + ", want " + std::to_string(camera.width) +
                                "x" + std::to_string(camera.height) + " of type " + std::to_string(type));
  }
  return OkStatus();
}

}  // namespace

double LayeredDepthView::LayerDepthAt(int layer, int x, int y) const {
  const int32_t index = layers[layer].segment.at<int32_t>(y, x);
  if (index == SegmentLayer::kNoSegment) return 0;
  return segments[index].DepthAt(x, y);
}

cv::Mat LayeredDepthView::DominantPlaneDepth() const {
  cv::Mat depth(camera.height, camera.width, CV_32F, cv::Scalar(0.0f));
  for (int y = 0; y < depth.rows; ++y) {
    const float* front_weight = layers[0].weight.ptr<float>(y);
    float* z = depth.ptr<float>(y);
    for (int x = 0; x < depth.cols; ++x) z[x] = static_cast<float>(LayerDepthAt(front_weight[x] >= 0.5f ? 0 : 1, x, y));
  }
  return depth;
}

DepthMap LayeredDepthView::ToDepthMap() const { return DepthMap{id, depth_m, confidence}; }

Status ValidateLayeredDepthView(const LayeredDepthView& view) {
  PX_RETURN_IF_ERROR(view.camera.Validate().WithContext(Where(view, -1)));
  PX_RETURN_IF_ERROR(CheckImage(view.depth_m, CV_32F, view.camera, Where(view, -1) + ": depth_m"));
  PX_RETURN_IF_ERROR(CheckImage(view.confidence, CV_32F, view.camera, Where(view, -1) + ": confidence"));
  const int num_segments = view.NumSegments();
  for (int i = 0; i < num_segments; ++i) {
    const DepthSegment& segment = view.segments[i];
    const std::string what = Where(view, -1) + ": segment " + std::to_string(i);
    if (!std::isfinite(segment.inv_depth_a) || !std::isfinite(segment.inv_depth_b) ||
        !std::isfinite(segment.inv_depth_c)) {
      return InvalidArgumentError(what + ": plane coefficients are not finite");
    }
    if ((segment.bbox & cv::Rect(0, 0, view.camera.width, view.camera.height)) != segment.bbox) {
      return InvalidArgumentError(what + ": bbox lies outside the view");
    }
    if (!(segment.confidence >= 0 && segment.confidence <= 1)) {
      return InvalidArgumentError(what + ": confidence " + Number(segment.confidence) + " is outside [0, 1]");
    }
    if (segment.num_pixels > 0) {
      const cv::Rect& b = segment.bbox;
      for (const cv::Point corner : {b.tl(),
                                     cv::Point(b.br().x - 1, b.y),
                                     cv::Point(b.x, b.br().y - 1),
                                     cv::Point(b.br().x - 1, b.br().y - 1)}) {
        if (segment.DepthAt(corner.x, corner.y) <= 0) {
          return InvalidArgumentError(what + ": its plane has no positive depth at bbox corner " +
                                      Pixel(corner.x, corner.y));
        }
      }
    }
  }
  for (int layer = 0; layer < 2; ++layer) {
    const SegmentLayer& l = view.layers[layer];
    PX_RETURN_IF_ERROR(CheckImage(l.colour, CV_8UC3, view.camera, Where(view, layer) + ": colour"));
    PX_RETURN_IF_ERROR(CheckImage(l.weight, CV_32F, view.camera, Where(view, layer) + ": weight"));
    PX_RETURN_IF_ERROR(CheckImage(l.segment, CV_32S, view.camera, Where(view, layer) + ": segment"));
  }
  constexpr float kSumTolerance = 1e-3f;
  for (int y = 0; y < view.camera.height; ++y) {
    for (int x = 0; x < view.camera.width; ++x) {
      float sum = 0;
      for (int layer = 0; layer < 2; ++layer) {
        const SegmentLayer& l = view.layers[layer];
        const float w = l.weight.at<float>(y, x);
        const int32_t s = l.segment.at<int32_t>(y, x);
        const std::string where = Where(view, layer) + ", " + Pixel(x, y);
        if (!(w >= 0 && w <= 1)) return InvalidArgumentError(where + ": weight " + Number(w) + " is outside [0, 1]");
        if (w > 0 && (s < 0 || s >= num_segments)) {
          return InvalidArgumentError(where + ": weight " + Number(w) + " but segment index " + std::to_string(s) +
                                      " is not one of the " + std::to_string(num_segments));
        }
        if (w > 0 && !view.segments[s].bbox.contains(cv::Point(x, y))) {
          return InvalidArgumentError(where + ": segment " + std::to_string(s) + " covers it outside its bbox");
        }
        sum += w;
      }
      if (sum > kSumTolerance && std::abs(sum - 1.0f) > kSumTolerance) {
        return InvalidArgumentError(Where(view, -1) + ", " + Pixel(x, y) + ": layer weights sum to " + Number(sum) +
                                    ", not 1");
      }
    }
  }
  return OkStatus();
}

}  // namespace px
