#include "pipeline/render/bilinear_prefilter.h"

#include <cmath>

namespace px::render {

std::array<cv::Mat, 2> PrefilterForBilinear(const LayeredDepthView& view, float sharpen) {
  const int width = view.camera.width, height = view.camera.height;
  std::array<cv::Mat, 2> out;
  // The colour that continues segment `s`'s surface at (x, y): the layer that holds `s` itself,
  // else one that holds a segment whose plane there is within kSameSurfaceTolerance of `s`'s (the
  // same surface cut by the segmentation); false when neither layer does.
  const auto colour_of = [&](int x, int y, int32_t s, cv::Vec3f* colour) {
    for (const SegmentLayer& l : view.layers) {
      if (l.segment.at<int32_t>(y, x) == s && l.weight.at<float>(y, x) > 0) {
        *colour = cv::Vec3f(l.colour.at<cv::Vec3b>(y, x));
        return true;
      }
    }
    // Indices are checked: the scene sanitises bad texels only after this.
    const int32_t count = view.NumSegments();
    if (s < 0 || s >= count) return false;
    const double own = view.segments[s].InverseDepthAt(x, y);
    if (!(own > 0)) return false;
    for (const SegmentLayer& l : view.layers) {
      const int32_t t = l.segment.at<int32_t>(y, x);
      if (t < 0 || t >= count || !(l.weight.at<float>(y, x) > 0)) continue;
      if (std::abs(view.segments[t].InverseDepthAt(x, y) - own) <= kSameSurfaceTolerance * own) {
        *colour = cv::Vec3f(l.colour.at<cv::Vec3b>(y, x));
        return true;
      }
    }
    return false;
  };
  for (int k = 0; k < 2; ++k) {
    const SegmentLayer& layer = view.layers[k];
    out[k] = layer.colour.clone();
    if (sharpen == 0) continue;
    for (int y = 0; y < height; ++y) {
      const int32_t* segment = layer.segment.ptr<int32_t>(y);
      const float* weight = layer.weight.ptr<float>(y);
      const cv::Vec3b* colour = layer.colour.ptr<cv::Vec3b>(y);
      cv::Vec3b* sharpened = out[k].ptr<cv::Vec3b>(y);
      for (int x = 0; x < width; ++x) {
        if (!(weight[x] > 0)) continue;
        const cv::Vec3f own(colour[x]);
        cv::Vec3f laplacian(0, 0, 0), neighbour;
        for (const cv::Point d : {cv::Point(-1, 0), cv::Point(1, 0), cv::Point(0, -1), cv::Point(0, 1)}) {
          const int xx = x + d.x, yy = y + d.y;
          if (xx < 0 || yy < 0 || xx >= width || yy >= height || !colour_of(xx, yy, segment[x], &neighbour)) continue;
          laplacian += own - neighbour;
        }
        const cv::Vec3f boosted = own + sharpen * laplacian;
        sharpened[x] = cv::Vec3b(cv::saturate_cast<uint8_t>(boosted[0]),
                                 cv::saturate_cast<uint8_t>(boosted[1]),
                                 cv::saturate_cast<uint8_t>(boosted[2]));
      }
    }
  }
  return out;
}

}  // namespace px::render
