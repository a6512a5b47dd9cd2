#include "pipeline/render/seam_skirts.h"

#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace px::render {

LayeredDepthView WithSeamSkirts(const LayeredDepthView& view,
                                const SeamSkirtOptions& options,
                                SeamSkirtReport* report) {
  if (report != nullptr) *report = SeamSkirtReport();
  const double max_step = options.max_step;
  if (!(max_step > 0)) return view;
  const int width = view.camera.width, height = view.camera.height;
  const SegmentLayer& front = view.layers[0];
  const SegmentLayer& back = view.layers[1];
  const auto sized = [&](const cv::Mat& m, int type) {
    return m.type() == type && m.cols == width && m.rows == height;
  };
  if (!sized(front.weight, CV_32F) || !sized(front.segment, CV_32S) || !sized(back.weight, CV_32F) ||
      !sized(back.segment, CV_32S) || !sized(back.colour, CV_8UC3) || !sized(front.colour, CV_8UC3)) {
    return view;  // the renderer's own checks name what is wrong
  }
  LayeredDepthView out = view;
  SegmentLayer& skirt = out.layers[1];
  skirt.weight = back.weight.clone();
  skirt.segment = back.segment.clone();
  skirt.colour = back.colour.clone();
  const int num_segments = view.NumSegments();
  const auto valid = [&](int32_t s) { return s >= 0 && s < num_segments; };
  constexpr std::array<std::array<int, 2>, 4> kNeighbours = {{{-1, 0}, {1, 0}, {0, -1}, {0, 1}}};
  // Texels of one segment alone, fully: not in a two-layer band, not empty.
  cv::Mat pure(height, width, CV_8U);
  for (int y = 0; y < height; ++y) {
    const float* weight0 = front.weight.ptr<float>(y);
    const int32_t* segment0 = front.segment.ptr<int32_t>(y);
    const float* weight1 = back.weight.ptr<float>(y);
    const int32_t* segment1 = back.segment.ptr<int32_t>(y);
    uint8_t* row = pure.ptr<uint8_t>(y);
    for (int x = 0; x < width; ++x) {
      row[x] = valid(segment0[x]) && weight0[x] >= 1.0f && segment1[x] == SegmentLayer::kNoSegment && weight1[x] == 0
                   ? 255
                   : 0;
    }
  }
  // Only texels whose 3x3 neighbourhood is pure and inside the image get a skirt: a bilinear
  // footprint (2x2) that reaches a band, an empty texel or the image's border then holds no skirt,
  // so soft edges, silhouettes and the frame's border keep their alpha exactly.
  cv::Mat skirtable;
  cv::erode(pure, skirtable, cv::Mat(), cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  int skirts = 0;
  for (int y = 0; y < height; ++y) {
    const int32_t* segment0 = front.segment.ptr<int32_t>(y);
    const uint8_t* can_skirt = skirtable.ptr<uint8_t>(y);
    for (int x = 0; x < width; ++x) {
      if (can_skirt[x] == 0) continue;
      const int32_t own = segment0[x];
      const double own_inverse = view.segments[own].InverseDepthAt(x, y);
      if (!(own_inverse > 0)) continue;
      // The neighbouring segment (original layer 0, fully there) whose plane is nearest this one's here.
      int32_t best = SegmentLayer::kNoSegment;
      double best_step = max_step;
      for (const auto& [dx, dy] : kNeighbours) {
        const int32_t other = front.segment.at<int32_t>(y + dy, x + dx);  // pure, inside: x, y are skirtable
        if (other == own) continue;
        const double step = std::abs(view.segments[other].InverseDepthAt(x, y) - own_inverse) / own_inverse;
        if (step < best_step && step >= options.min_step) {
          best_step = step;
          best = other;
        }
      }
      if (best == SegmentLayer::kNoSegment) continue;
      skirt.segment.at<int32_t>(y, x) = best;
      skirt.weight.at<float>(y, x) = options.weight;
      skirt.colour.at<cv::Vec3b>(y, x) = front.colour.at<cv::Vec3b>(y, x);
      DepthSegment& grown = out.segments[best];
      grown.bbox |= cv::Rect(x, y, 1, 1);
      ++grown.num_pixels;
      ++skirts;
    }
  }
  if (report != nullptr) report->skirt_texels = skirts;
  return out;
}

}  // namespace px::render
