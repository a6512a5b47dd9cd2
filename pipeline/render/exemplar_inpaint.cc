#include "pipeline/render/exemplar_inpaint.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "pipeline/core/check.h"

namespace px::render {
namespace {

enum : uint8_t {
  kHole = 0,         // this component, not yet filled
  kBackground = 1,   // originally known, background cluster
  kForeground = 2,   // originally known, foreground cluster
  kFilled = 3,       // filled by this run
  kUnavailable = 4,  // unknown and not this component (another hole): never read
};

// 1D k-means with k = 2, initialised at the extremes: the two cluster means.
void TwoMeans(const std::vector<float>& values, float* near_mean, float* far_mean) {
  float lo = *std::min_element(values.begin(), values.end());
  float hi = *std::max_element(values.begin(), values.end());
  for (int iteration = 0; iteration < 20 && lo < hi; ++iteration) {
    const float split = 0.5f * (lo + hi);
    double sum_lo = 0, sum_hi = 0;
    int n_lo = 0, n_hi = 0;
    for (float v : values) {
      if (v < split) {
        sum_lo += v;
        ++n_lo;
      } else {
        sum_hi += v;
        ++n_hi;
      }
    }
    const float new_lo = n_lo > 0 ? static_cast<float>(sum_lo / n_lo) : lo;
    const float new_hi = n_hi > 0 ? static_cast<float>(sum_hi / n_hi) : hi;
    if (new_lo == lo && new_hi == hi) break;
    lo = new_lo;
    hi = new_hi;
  }
  *near_mean = lo;
  *far_mean = hi;
}

inline float Grey(const cv::Vec3f& c) { return 0.114f * c[0] + 0.587f * c[1] + 0.299f * c[2]; }

// One connected hole, worked on inside a region of interest around it.
class ComponentFill {
 public:
  ComponentFill(const SoftZ& soft_z,
                const InpaintOptions& options,
                cv::Mat status,
                cv::Mat colour,
                cv::Mat depth,
                InpaintReport* report)
      : soft_z_(soft_z),
        options_(options),
        status_(std::move(status)),
        colour_(std::move(colour)),
        depth_(std::move(depth)),
        confidence_(status_.size(), CV_32F, cv::Scalar(0)),
        report_(report) {}

  void Run() {
    const int r = options_.patch_radius_px;
    const int side = 2 * r + 1;
    // Valid source centres: the whole patch originally known background.
    cv::Mat background = status_ == kBackground;
    cv::Mat counts;
    cv::boxFilter(
        background / 255, counts, CV_32F, cv::Size(side, side), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
    source_ok_ = counts >= static_cast<float>(side * side) - 0.5f;
    for (int y = 0; y < status_.rows; ++y) {
      uint8_t* ok = source_ok_.ptr<uint8_t>(y);
      for (int x = 0; x < status_.cols; ++x) {
        if (x < r || y < r || x >= status_.cols - r || y >= status_.rows - r) ok[x] = 0;
      }
    }
    confidence_.setTo(1.0f, background);
    // The front: hole pixels next to anything known or filled.
    std::vector<cv::Point> front;
    for (int y = 0; y < status_.rows; ++y) {
      for (int x = 0; x < status_.cols; ++x) {
        if (status_.at<uint8_t>(y, x) == kHole && OnFront(x, y)) front.emplace_back(x, y);
      }
    }
    in_front_ = cv::Mat::zeros(status_.size(), CV_8U);
    for (const cv::Point& p : front) in_front_.at<uint8_t>(p) = 1;
    while (!front.empty()) {
      // Highest priority; ties: smallest y, then x.
      int best = -1;
      float best_priority = -1;
      size_t write = 0;
      for (size_t i = 0; i < front.size(); ++i) {
        const cv::Point p = front[i];
        if (status_.at<uint8_t>(p) != kHole) {
          in_front_.at<uint8_t>(p) = 0;
          continue;
        }
        front[write++] = p;
        const float priority = Priority(p.x, p.y);
        if (priority > best_priority ||
            (priority == best_priority && (p.y < front[best].y || (p.y == front[best].y && p.x < front[best].x)))) {
          best_priority = priority;
          best = static_cast<int>(write - 1);
        }
      }
      front.resize(write);
      if (best < 0) break;
      const cv::Point target = front[best];
      FillPatch(target.x, target.y);
      // New front pixels around the patch.
      for (int y = std::max(0, target.y - r - 1); y <= std::min(status_.rows - 1, target.y + r + 1); ++y) {
        for (int x = std::max(0, target.x - r - 1); x <= std::min(status_.cols - 1, target.x + r + 1); ++x) {
          if (status_.at<uint8_t>(y, x) == kHole && !in_front_.at<uint8_t>(y, x) && OnFront(x, y)) {
            in_front_.at<uint8_t>(y, x) = 1;
            front.emplace_back(x, y);
          }
        }
      }
    }
  }

 private:
  bool KnownOrFilled(int x, int y) const {
    const uint8_t s = status_.at<uint8_t>(y, x);
    return s == kBackground || s == kForeground || s == kFilled;
  }
  bool OnFront(int x, int y) const {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int xx = x + dx, yy = y + dy;
        if (xx < 0 || yy < 0 || xx >= status_.cols || yy >= status_.rows) continue;
        if (KnownOrFilled(xx, yy)) return true;
      }
    }
    return false;
  }

  // Criminisi's P = C D: confidence of the patch times the isophote's strength across the front.
  float Priority(int px, int py) const {
    const int r = options_.patch_radius_px;
    const float area = static_cast<float>((2 * r + 1) * (2 * r + 1));
    float c = 0;
    float best_gx = 0, best_gy = 0, best_magnitude = 0;
    for (int y = py - r; y <= py + r; ++y) {
      for (int x = px - r; x <= px + r; ++x) {
        if (x < 0 || y < 0 || x >= status_.cols || y >= status_.rows) continue;
        const uint8_t s = status_.at<uint8_t>(y, x);
        if (s == kBackground || s == kFilled) c += confidence_.at<float>(y, x);
        if (s != kBackground && s != kFilled) continue;
        float gx = 0, gy = 0;
        if (Gradient(x, y, &gx, &gy) && gx * gx + gy * gy > best_magnitude) {
          best_magnitude = gx * gx + gy * gy;
          best_gx = gx;
          best_gy = gy;
        }
      }
    }
    // Normal of the front: the gradient of the known-or-filled mask (Sobel 3x3).
    float nx = 0, ny = 0;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = px + dx, y = py + dy;
        if (x < 0 || y < 0 || x >= status_.cols || y >= status_.rows || !KnownOrFilled(x, y)) continue;
        const float wy = dy == 0 ? 2.0f : 1.0f, wx = dx == 0 ? 2.0f : 1.0f;
        nx += static_cast<float>(dx) * wy;
        ny += static_cast<float>(dy) * wx;
      }
    }
    const float norm = std::sqrt(nx * nx + ny * ny);
    float data = 0;
    if (norm > 0) data = std::abs(-best_gy * nx / norm + best_gx * ny / norm) / 255.0f;  // isophote = (-gy, gx)
    return (c / area) * (data + 0.001f);
  }

  // Sobel gradient of the grey image at (x, y) when its 3x3 neighbourhood is background or filled
  // (a foreground edge is not an isophote of what is being filled).
  bool Gradient(int x, int y, float* gx, float* gy) const {
    if (x < 1 || y < 1 || x >= status_.cols - 1 || y >= status_.rows - 1) return false;
    float g[3][3];
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const uint8_t s = status_.at<uint8_t>(y + dy, x + dx);
        if (s != kBackground && s != kFilled) return false;
        g[dy + 1][dx + 1] = Grey(colour_.at<cv::Vec3f>(y + dy, x + dx));
      }
    }
    *gx = (g[0][2] + 2 * g[1][2] + g[2][2] - g[0][0] - 2 * g[1][0] - g[2][0]) / 8.0f;
    *gy = (g[2][0] + 2 * g[2][1] + g[2][2] - g[0][0] - 2 * g[0][1] - g[0][2]) / 8.0f;
    return true;
  }

  // The best source centre for the patch at (px, py) within `radius` (-1, -1 if none).
  cv::Point BestSource(int px, int py, int radius) const {
    const int r = options_.patch_radius_px;
    // Compared pixels: known-or-filled and not foreground; if there are none, any known or filled.
    std::vector<cv::Point> offsets;
    for (int pass = 0; pass < 2 && offsets.empty(); ++pass) {
      for (int dy = -r; dy <= r; ++dy) {
        for (int dx = -r; dx <= r; ++dx) {
          const int x = px + dx, y = py + dy;
          if (x < 0 || y < 0 || x >= status_.cols || y >= status_.rows) continue;
          const uint8_t s = status_.at<uint8_t>(y, x);
          if (s == kBackground || s == kFilled || (pass == 1 && s == kForeground)) offsets.emplace_back(dx, dy);
        }
      }
    }
    cv::Point best(-1, -1);
    float best_distance = std::numeric_limits<float>::infinity();
    const int y0 = std::max(r, py - radius), y1 = std::min(status_.rows - 1 - r, py + radius);
    const int x0 = std::max(r, px - radius), x1 = std::min(status_.cols - 1 - r, px + radius);
    for (int cy = y0; cy <= y1; ++cy) {
      const uint8_t* ok = source_ok_.ptr<uint8_t>(cy);
      for (int cx = x0; cx <= x1; ++cx) {
        if (!ok[cx]) continue;
        float distance = 0;
        for (const cv::Point& o : offsets) {
          const cv::Vec3f d = colour_.at<cv::Vec3f>(py + o.y, px + o.x) - colour_.at<cv::Vec3f>(cy + o.y, cx + o.x);
          distance += d.dot(d);
          if (distance >= best_distance) break;
        }
        if (distance < best_distance) {
          best_distance = distance;
          best = cv::Point(cx, cy);
        }
      }
    }
    return best;
  }

  // Depth of a newly filled pixel: reverse soft z over the known-or-filled depths around it.
  bool BlendDepth(int px, int py, float* z_out, cv::Vec3f* colour_out) const {
    const int r = options_.depth_radius_px;
    float z_far = -std::numeric_limits<float>::infinity();
    for (int y = std::max(0, py - r); y <= std::min(status_.rows - 1, py + r); ++y) {
      for (int x = std::max(0, px - r); x <= std::min(status_.cols - 1, px + r); ++x) {
        if (KnownOrFilled(x, y)) z_far = std::max(z_far, depth_.at<float>(y, x));
      }
    }
    if (!(z_far > -std::numeric_limits<float>::infinity())) return false;
    float sum_w = 0, sum_z = 0;
    cv::Vec3f sum_c(0, 0, 0);
    for (int y = std::max(0, py - r); y <= std::min(status_.rows - 1, py + r); ++y) {
      for (int x = std::max(0, px - r); x <= std::min(status_.cols - 1, px + r); ++x) {
        if (!KnownOrFilled(x, y)) continue;
        const float w = soft_z_.Weight(z_far - depth_.at<float>(y, x));
        sum_w += w;
        sum_z += w * depth_.at<float>(y, x);
        sum_c += w * colour_.at<cv::Vec3f>(y, x);
      }
    }
    if (!(sum_w > 0)) return false;
    *z_out = sum_z / sum_w;
    if (colour_out != nullptr) *colour_out = sum_c * (1.0f / sum_w);
    return true;
  }

  void FillPatch(int px, int py) {
    const int r = options_.patch_radius_px;
    float c = 0;
    for (int y = py - r; y <= py + r; ++y) {
      for (int x = px - r; x <= px + r; ++x) {
        if (x < 0 || y < 0 || x >= status_.cols || y >= status_.rows) continue;
        const uint8_t s = status_.at<uint8_t>(y, x);
        if (s == kBackground || s == kFilled) c += confidence_.at<float>(y, x);
      }
    }
    c /= static_cast<float>((2 * r + 1) * (2 * r + 1));
    cv::Point source = BestSource(px, py, options_.window_radius_px);
    if (source.x < 0) source = BestSource(px, py, std::max(status_.rows, status_.cols));
    std::vector<cv::Point> filled;
    for (int dy = -r; dy <= r; ++dy) {
      for (int dx = -r; dx <= r; ++dx) {
        const int x = px + dx, y = py + dy;
        if (x < 0 || y < 0 || x >= status_.cols || y >= status_.rows || status_.at<uint8_t>(y, x) != kHole) continue;
        if (source.x >= 0) {
          colour_.at<cv::Vec3f>(y, x) = colour_.at<cv::Vec3f>(source.y + dy, source.x + dx);
          filled.emplace_back(x, y);
        } else if (dx == 0 && dy == 0) {
          // No background anywhere: the reverse soft z blend of the neighbourhood instead.
          float z = 0;
          cv::Vec3f blended;
          if (BlendDepth(x, y, &z, &blended)) {
            colour_.at<cv::Vec3f>(y, x) = blended;
            depth_.at<float>(y, x) = z;
            status_.at<uint8_t>(y, x) = kFilled;
            confidence_.at<float>(y, x) = c;
            ++report_->fallback_pixels;
            ++report_->pixels;
          } else {
            status_.at<uint8_t>(y, x) = kUnavailable;  // cannot happen on the front; never loop on it
          }
        }
      }
    }
    if (source.x < 0) return;
    ++report_->patches;
    // Depths after all colours are in, each from the pixels known or filled before this patch and
    // the ones of this patch already given a depth.
    for (const cv::Point& p : filled) {
      float z = depth_.at<float>(source.y + p.y - py, source.x + p.x - px);
      BlendDepth(p.x, p.y, &z, nullptr);
      depth_.at<float>(p) = z;
      status_.at<uint8_t>(p) = kFilled;
      confidence_.at<float>(p) = c;
      ++report_->pixels;
    }
  }

  const SoftZ& soft_z_;
  InpaintOptions options_;
  cv::Mat status_;
  cv::Mat colour_;  // views into the caller's images (ROI)
  cv::Mat depth_;
  cv::Mat confidence_;
  cv::Mat source_ok_;
  cv::Mat in_front_;
  InpaintReport* report_;
};

}  // namespace

InpaintReport InpaintDepthAware(const SoftZ& soft_z,
                                const InpaintOptions& options,
                                const cv::Mat& target,
                                cv::Mat* known,
                                cv::Mat* colour,
                                cv::Mat* depth) {
  PX_CHECK(known != nullptr && colour != nullptr && depth != nullptr) << "InpaintDepthAware needs outputs";
  PX_CHECK(target.type() == CV_8U && known->type() == CV_8U && colour->type() == CV_32FC3 && depth->type() == CV_32F)
      << "InpaintDepthAware types";
  InpaintReport report;
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(target != 0, labels, stats, centroids, 8, CV_32S);
  const int margin = options.window_radius_px + options.patch_radius_px + 1;
  for (int label = 1; label < count; ++label) {
    const cv::Rect box(stats.at<int>(label, cv::CC_STAT_LEFT),
                       stats.at<int>(label, cv::CC_STAT_TOP),
                       stats.at<int>(label, cv::CC_STAT_WIDTH),
                       stats.at<int>(label, cv::CC_STAT_HEIGHT));
    if (!options.fill_border_holes &&
        (box.x == 0 || box.y == 0 || box.x + box.width == target.cols || box.y + box.height == target.rows)) {
      ++report.border_components;
      continue;
    }
    const cv::Rect roi = cv::Rect(box.x - margin, box.y - margin, box.width + 2 * margin, box.height + 2 * margin) &
                         cv::Rect(0, 0, target.cols, target.rows);
    // Boundary depths: known pixels 8-adjacent to this component.
    std::vector<float> boundary;
    cv::Mat status(roi.size(), CV_8U);
    for (int y = 0; y < roi.height; ++y) {
      const int* l = labels.ptr<int>(y + roi.y) + roi.x;
      const uint8_t* k = known->ptr<uint8_t>(y + roi.y) + roi.x;
      const uint8_t* t = target.ptr<uint8_t>(y + roi.y) + roi.x;
      uint8_t* s = status.ptr<uint8_t>(y);
      for (int x = 0; x < roi.width; ++x) {
        if (l[x] == label) {
          s[x] = kHole;
        } else if (k[x] != 0 && t[x] == 0) {
          s[x] = kBackground;
        } else {
          s[x] = kUnavailable;
        }
      }
    }
    for (int y = 0; y < roi.height; ++y) {
      for (int x = 0; x < roi.width; ++x) {
        if (status.at<uint8_t>(y, x) != kBackground) continue;
        bool next_to_hole = false;
        for (int dy = -1; dy <= 1 && !next_to_hole; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx, yy = y + dy;
            if (xx >= 0 && yy >= 0 && xx < roi.width && yy < roi.height && status.at<uint8_t>(yy, xx) == kHole) {
              next_to_hole = true;
              break;
            }
          }
        }
        if (next_to_hole) boundary.push_back(depth->at<float>(y + roi.y, x + roi.x));
      }
    }
    if (boundary.empty()) continue;  // nothing known around it (cannot happen: it is a hole of a frame)
    float near_mean = 0, far_mean = 0;
    TwoMeans(boundary, &near_mean, &far_mean);
    if (far_mean - near_mean >= soft_z.gamma()) {
      ++report.two_layer_components;
      const float split = 0.5f * (near_mean + far_mean);
      for (int y = 0; y < roi.height; ++y) {
        for (int x = 0; x < roi.width; ++x) {
          if (status.at<uint8_t>(y, x) == kBackground && depth->at<float>(y + roi.y, x + roi.x) < split) {
            status.at<uint8_t>(y, x) = kForeground;
          }
        }
      }
    }
    ++report.components;
    ComponentFill fill(soft_z, options, status, (*colour)(roi), (*depth)(roi), &report);
    fill.Run();
    for (int y = 0; y < roi.height; ++y) {
      for (int x = 0; x < roi.width; ++x) {
        if (labels.at<int>(y + roi.y, x + roi.x) == label && status.at<uint8_t>(y, x) == kFilled) {
          known->at<uint8_t>(y + roi.y, x + roi.x) = 255;
        }
      }
    }
  }
  return report;
}

}  // namespace px::render
