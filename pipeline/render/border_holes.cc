#include "pipeline/render/border_holes.h"

#include <array>
#include <cmath>
#include <cstdlib>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <vector>

#include "pipeline/core/check.h"

namespace px::render {
namespace {

// A side of the frame: the step going in from it, and the step along it.
struct Side {
  cv::Point in;
  cv::Point along;
};
const std::array<Side, 4> kSides = {{{{1, 0}, {0, 1}},     // left
                                     {{0, 1}, {1, 0}},     // top
                                     {{-1, 0}, {0, 1}},    // right
                                     {{0, -1}, {1, 0}}}};  // bottom

// Distance of `p` from side `s` of an image of `size`.
int DistanceFromSide(int s, cv::Point p, cv::Size size) {
  switch (s) {
    case 0:
      return p.x;
    case 1:
      return p.y;
    case 2:
      return size.width - 1 - p.x;
    default:
      return size.height - 1 - p.y;
  }
}

bool Inside(cv::Point p, cv::Size size) { return p.x >= 0 && p.y >= 0 && p.x < size.width && p.y < size.height; }

// Steps going in from one side to the first known pixel, per pixel, worked out as asked for and
// kept: each walk records its answer on every pixel it passed, so a line is walked once.
class StepsToKnown {
 public:
  StepsToKnown(const cv::Mat& known, cv::Point in)
      : known_(known), in_(in), steps_(known.size(), CV_32S, cv::Scalar(kNotYet)) {}

  // Steps from `p` to the first known pixel going in (0 on a known one); -1 if the line leaves
  // the image first.
  int At(cv::Point p) {
    if (const int cached = steps_.at<int>(p); cached != kNotYet) return cached;
    path_.clear();
    int found = -1;
    for (cv::Point q = p; Inside(q, known_.size()); q += in_) {
      const int cached = steps_.at<int>(q);
      if (cached != kNotYet) {
        found = cached;
        break;
      }
      if (known_.at<uint8_t>(q) != 0) {
        found = 0;
        steps_.at<int>(q) = 0;
        break;
      }
      path_.push_back(q);
    }
    for (size_t i = path_.size(); i-- > 0;) {
      if (found >= 0) ++found;
      steps_.at<int>(path_[i]) = found;
    }
    return steps_.at<int>(p);
  }

 private:
  static constexpr int kNotYet = -2;
  const cv::Mat& known_;
  cv::Point in_;
  cv::Mat steps_;
  std::vector<cv::Point> path_;
};

}  // namespace

FrameSides SidesOnFrameBorder(const cv::Rect& box, const cv::Size& frame_size) {
  FrameSides sides;
  sides.left = box.x == 0;
  sides.top = box.y == 0;
  sides.right = box.x + box.width == frame_size.width;
  sides.bottom = box.y + box.height == frame_size.height;
  return sides;
}

int FillBorderHoles(
    const FrameSides& sides, const BorderHoleFillOptions& options, cv::Mat* known, cv::Mat* colour, cv::Mat* depth) {
  PX_CHECK(known != nullptr && colour != nullptr && depth != nullptr) << "FillBorderHoles needs outputs";
  PX_CHECK(known->type() == CV_8U && colour->type() == CV_32FC3 && depth->type() == CV_32F)
      << "FillBorderHoles types " << known->type() << " " << colour->type() << " " << depth->type();
  PX_CHECK(known->size() == colour->size() && known->size() == depth->size()) << "FillBorderHoles sizes differ";
  const cv::Size size = known->size();
  const cv::Mat holes = *known == 0;
  if (cv::countNonZero(holes) == 0 || cv::countNonZero(*known) == 0) return 0;
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(holes, labels, stats, centroids, 8, CV_32S);
  const std::array<bool, 4> on_border = {sides.left, sides.top, sides.right, sides.bottom};
  // Sides each hole touches (bit s), among those on the frame's border.
  std::vector<int> touched(count, 0);
  int all_touched = 0;
  for (int label = 1; label < count; ++label) {
    const int x = stats.at<int>(label, cv::CC_STAT_LEFT), y = stats.at<int>(label, cv::CC_STAT_TOP);
    const int w = stats.at<int>(label, cv::CC_STAT_WIDTH), h = stats.at<int>(label, cv::CC_STAT_HEIGHT);
    const std::array<bool, 4> reaches = {x == 0, y == 0, x + w == size.width, y + h == size.height};
    for (int s = 0; s < 4; ++s) {
      if (reaches[s] && on_border[s]) touched[label] |= 1 << s;
    }
    all_touched |= touched[label];
  }
  if (all_touched == 0) return 0;
  std::array<std::optional<StepsToKnown>, 4> steps;
  for (int s = 0; s < 4; ++s) {
    if ((all_touched & (1 << s)) != 0) steps[s].emplace(*known, kSides[s].in);
  }
  struct Fill {
    cv::Point at;
    cv::Vec3f colour;
    float depth;
  };
  std::vector<Fill> fills;
  for (int y = 0; y < size.height; ++y) {
    const int* l = labels.ptr<int>(y);
    for (int x = 0; x < size.width; ++x) {
      if (l[x] == 0 || touched[l[x]] == 0) continue;
      const cv::Point p(x, y);
      // The nearest touched side whose line in from p meets a known pixel.
      int side = -1;
      for (int s = 0; s < 4; ++s) {
        if ((touched[l[x]] & (1 << s)) == 0 || steps[s]->At(p) < 0) continue;
        if (side < 0 || DistanceFromSide(s, p, size) < DistanceFromSide(side, p, size)) side = s;
      }
      if (side < 0) continue;
      StepsToKnown& to_known = *steps[side];
      const int reach = static_cast<int>(std::floor(options.spread * static_cast<float>(to_known.At(p))));
      cv::Vec3f sum_colour(0, 0, 0);
      float sum_depth = 0, sum_w = 0;
      for (int j = -reach; j <= reach; ++j) {
        const cv::Point start = p + j * kSides[side].along;
        if (!Inside(start, size) || to_known.At(start) < 0) continue;
        const cv::Point q = start + to_known.At(start) * kSides[side].in;
        // A triangle: the lines nearest p's count most.
        const float w = static_cast<float>(reach + 1 - std::abs(j));
        sum_colour += w * colour->at<cv::Vec3f>(q);
        sum_depth += w * depth->at<float>(q);
        sum_w += w;
      }
      if (sum_w > 0) fills.push_back({p, sum_colour * (1.0f / sum_w), sum_depth / sum_w});
    }
  }
  for (const Fill& f : fills) {
    colour->at<cv::Vec3f>(f.at) = f.colour;
    depth->at<float>(f.at) = f.depth;
    known->at<uint8_t>(f.at) = 255;
  }
  return static_cast<int>(fills.size());
}

}  // namespace px::render
