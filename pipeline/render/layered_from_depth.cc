#include "pipeline/render/layered_from_depth.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace px {
namespace {

constexpr int kMaxClustersPerBlock = 4;

struct BlockPixel {
  int x, y;
  float inv;  // 1 / z
};

// Fits 1/z = a x + b y + c by least squares; a fronto-parallel plane at the mean when the pixels
// do not pin a plane down, or when the fit is not positive over `extent` (the block grown by the
// pixel the renderer grows every segment's rectangle by).
DepthSegment FitPlane(const std::vector<BlockPixel>& pixels, const cv::Rect& box, const cv::Rect& extent) {
  DepthSegment segment;
  double mean = 0;
  for (const BlockPixel& p : pixels) mean += p.inv;
  mean /= static_cast<double>(pixels.size());
  segment.inv_depth_c = mean;
  if (pixels.size() >= 3) {
    // Centred coordinates keep the normal equations well conditioned.
    const double cx = box.x + 0.5 * (box.width - 1), cy = box.y + 0.5 * (box.height - 1);
    Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
    Eigen::Vector3d atb = Eigen::Vector3d::Zero();
    for (const BlockPixel& p : pixels) {
      const Eigen::Vector3d row(p.x - cx, p.y - cy, 1.0);
      ata += row * row.transpose();
      atb += row * p.inv;
    }
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(ata);
    if (lu.rank() == 3) {
      const Eigen::Vector3d abc = lu.solve(atb);
      DepthSegment fitted;
      fitted.inv_depth_a = abc(0);
      fitted.inv_depth_b = abc(1);
      fitted.inv_depth_c = abc(2) - abc(0) * cx - abc(1) * cy;
      bool positive = true;
      for (const cv::Point corner : {extent.tl(),
                                     cv::Point(extent.br().x - 1, extent.y),
                                     cv::Point(extent.x, extent.br().y - 1),
                                     cv::Point(extent.br().x - 1, extent.br().y - 1)}) {
        positive = positive && fitted.InverseDepthAt(corner.x, corner.y) > 1e-3 * mean;
      }
      if (positive) segment = fitted;
    }
  }
  return segment;
}

// Splits sorted inverse depths at their largest gaps while a part spans more than `ratio` of its
// largest value: the index ranges of the parts, nearest (largest inverse depth) last.
std::vector<std::pair<int, int>> SplitAtGaps(const std::vector<float>& sorted, double ratio) {
  std::vector<std::pair<int, int>> parts = {{0, static_cast<int>(sorted.size())}};
  for (bool split = true; split && static_cast<int>(parts.size()) < kMaxClustersPerBlock;) {
    split = false;
    for (size_t i = 0; i < parts.size(); ++i) {
      const auto [begin, end] = parts[i];
      if (end - begin < 2 || sorted[end - 1] - sorted[begin] <= ratio * sorted[end - 1]) continue;
      int cut = begin + 1;
      for (int k = begin + 1; k < end; ++k) {
        if (sorted[k] - sorted[k - 1] > sorted[cut] - sorted[cut - 1]) cut = k;
      }
      parts[i] = {begin, cut};
      parts.insert(parts.begin() + static_cast<std::ptrdiff_t>(i) + 1, {cut, end});
      split = true;
      break;
    }
  }
  return parts;
}

}  // namespace

StatusOr<LayeredDepthView> LayeredDepthFromDepthMap(const View& view,
                                                    const DepthMap& depth,
                                                    const LayeredFromDepthOptions& options) {
  const std::string name = "layered depth of view " + std::to_string(view.id.value);
  if (options.block_px < 2 || options.block_px > 64) {
    return InvalidArgumentError(name + ": block_px " + std::to_string(options.block_px) + " is outside [2, 64]");
  }
  if (!(options.jump_ratio > 0 && options.jump_ratio <= 1)) {
    return InvalidArgumentError(name + ": jump_ratio " + std::to_string(options.jump_ratio) + " is outside (0, 1]");
  }
  if (!(options.edge_front_weight > 0 && options.edge_front_weight <= 1)) {
    return InvalidArgumentError(name + ": edge_front_weight " + std::to_string(options.edge_front_weight) +
                                " is outside (0, 1]");
  }
  PX_RETURN_IF_ERROR(view.camera.Validate().WithContext(name));
  if (view.camera.HasDistortion()) return InvalidArgumentError(name + ": camera has lens distortion");
  const int width = view.camera.width, height = view.camera.height;
  if (view.image.type() != CV_8UC3 || view.image.cols != width || view.image.rows != height) {
    return InvalidArgumentError(name + ": image is " + std::to_string(view.image.cols) + "x" +
                                std::to_string(view.image.rows) + " of type " + std::to_string(view.image.type()) +
                                ", want CV_8UC3 of the camera's size");
  }
  if (depth.depth_m.type() != CV_32F || depth.depth_m.size() != view.image.size()) {
    return InvalidArgumentError(name + ": depth map must be CV_32F of the image's size");
  }
  if (!depth.confidence.empty() &&
      (depth.confidence.type() != CV_32F || depth.confidence.size() != view.image.size())) {
    return InvalidArgumentError(name + ": confidence must be CV_32F of the image's size, or empty");
  }

  LayeredDepthView out;
  out.id = view.id;
  out.camera = view.camera;
  for (SegmentLayer& layer : out.layers) {
    layer.colour = cv::Mat::zeros(height, width, CV_8UC3);
    layer.weight = cv::Mat::zeros(height, width, CV_32F);
    layer.segment = cv::Mat(height, width, CV_32S, cv::Scalar(SegmentLayer::kNoSegment));
  }
  out.depth_m = cv::Mat::zeros(height, width, CV_32F);
  out.confidence =
      depth.confidence.empty() ? cv::Mat(height, width, CV_32F, cv::Scalar(1.0f)) : depth.confidence.clone();
  cv::Mat cluster_of(height, width, CV_32S, cv::Scalar(-1));  // segment index per pixel

  const int b = options.block_px;
  std::vector<BlockPixel> pixels;
  std::vector<float> sorted;
  for (int by = 0; by < height; by += b) {
    for (int bx = 0; bx < width; bx += b) {
      const cv::Rect block = cv::Rect(bx, by, b, b) & cv::Rect(0, 0, width, height);
      pixels.clear();
      for (int y = block.y; y < block.br().y; ++y) {
        const float* z = depth.depth_m.ptr<float>(y);
        for (int x = block.x; x < block.br().x; ++x) {
          if (z[x] > 0 && std::isfinite(z[x])) pixels.push_back({x, y, 1.0f / z[x]});
        }
      }
      if (pixels.empty()) continue;
      sorted.clear();
      for (const BlockPixel& p : pixels) sorted.push_back(p.inv);
      std::sort(sorted.begin(), sorted.end());
      const std::vector<std::pair<int, int>> parts = SplitAtGaps(sorted, options.jump_ratio);
      for (const auto& [begin, end] : parts) {
        const float lo = sorted[begin], hi = sorted[end - 1];
        std::vector<BlockPixel> members;
        cv::Rect box;
        for (const BlockPixel& p : pixels) {
          if (p.inv < lo || p.inv > hi) continue;
          members.push_back(p);
          box = box.area() == 0 ? cv::Rect(p.x, p.y, 1, 1) : (box | cv::Rect(p.x, p.y, 1, 1));
        }
        if (members.empty()) continue;
        DepthSegment segment =
            FitPlane(members, box, cv::Rect(block.x - 1, block.y - 1, block.width + 2, block.height + 2));
        segment.bbox = box;
        segment.num_pixels = static_cast<int32_t>(members.size());
        const int index = out.NumSegments();
        for (const BlockPixel& p : members) cluster_of.at<int32_t>(p.y, p.x) = index;
        float confidence = 0;
        for (const BlockPixel& p : members) confidence += out.confidence.at<float>(p.y, p.x);
        segment.confidence = std::clamp(confidence / static_cast<float>(members.size()), 0.0f, 1.0f);
        out.segments.push_back(segment);
      }
    }
  }

  // Layers: every covered pixel's own segment in front; along a jump inside a block, the far
  // segment behind the near pixel.
  const float front = static_cast<float>(options.edge_front_weight);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const int s = cluster_of.at<int32_t>(y, x);
      if (s < 0) continue;
      const cv::Vec3b colour = view.image.at<cv::Vec3b>(y, x);
      out.layers[0].segment.at<int32_t>(y, x) = s;
      out.layers[0].colour.at<cv::Vec3b>(y, x) = colour;
      out.layers[0].weight.at<float>(y, x) = 1.0f;
      out.depth_m.at<float>(y, x) = static_cast<float>(out.segments[s].DepthAt(x, y));
      if (front >= 1.0f) continue;
      const int bx = x / b, by = y / b;
      int behind = -1;
      double behind_depth = out.segments[s].DepthAt(x, y);
      for (const cv::Point d : {cv::Point(-1, 0), cv::Point(1, 0), cv::Point(0, -1), cv::Point(0, 1)}) {
        const int xx = x + d.x, yy = y + d.y;
        if (xx < 0 || yy < 0 || xx >= width || yy >= height || xx / b != bx || yy / b != by) continue;
        const int t = cluster_of.at<int32_t>(yy, xx);
        if (t < 0 || t == s) continue;
        const double z = out.segments[t].DepthAt(x, y);
        if (z > behind_depth) {
          behind = t;
          behind_depth = z;
        }
      }
      if (behind < 0) continue;
      out.layers[0].weight.at<float>(y, x) = front;
      out.layers[1].segment.at<int32_t>(y, x) = behind;
      out.layers[1].colour.at<cv::Vec3b>(y, x) = colour;
      out.layers[1].weight.at<float>(y, x) = 1.0f - front;
      out.segments[behind].bbox |= cv::Rect(x, y, 1, 1);
      ++out.segments[behind].num_pixels;
    }
  }
  return out;
}

}  // namespace px
