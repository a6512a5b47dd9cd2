#include "pipeline/depth/two_layer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/check.h"

namespace px::depth {
namespace {

constexpr int32_t kNone = SegmentLayer::kNoSegment;

// Replaces planes that reach too small (or negative) inverse depth anywhere in `box` by a
// fronto-parallel plane at their value at `centre`.
void KeepPositive(const cv::Rect& box, const cv::Point2d& centre, double min_inverse, InversePlane* plane) {
  const double corners[4] = {plane->At(box.x, box.y),
                             plane->At(box.br().x - 1, box.y),
                             plane->At(box.x, box.br().y - 1),
                             plane->At(box.br().x - 1, box.br().y - 1)};
  if (*std::min_element(corners, corners + 4) >= min_inverse) return;
  InversePlane fronto;
  fronto.c = std::max(plane->At(centre.x, centre.y), min_inverse);
  *plane = fronto;
}

// Per pixel: the segment across the strongest depth edge it lies on (kNone when none), from
// comparing each pair of 4-neighbours with different labels at their shared border.
cv::Mat FindDepthEdges(const cv::Mat& labels, const std::vector<InversePlane>& planes, double threshold) {
  cv::Mat other(labels.size(), CV_32S, cv::Scalar(kNone));
  cv::Mat jump(labels.size(), CV_32F, cv::Scalar(0));
  const auto mark = [&](int x, int y, int32_t across, double size) {
    if (size > jump.at<float>(y, x)) {
      jump.at<float>(y, x) = static_cast<float>(size);
      other.at<int32_t>(y, x) = across;
    }
  };
  for (int y = 0; y < labels.rows; ++y) {
    const int32_t* l = labels.ptr<int32_t>(y);
    const int32_t* below = y + 1 < labels.rows ? labels.ptr<int32_t>(y + 1) : nullptr;
    for (int x = 0; x < labels.cols; ++x) {
      const auto compare = [&](int32_t a, int32_t b, double mx, double my, int bx, int by) {
        if (a == b) return;
        const double size = std::abs(planes[a].At(mx, my) - planes[b].At(mx, my));
        if (size <= threshold) return;
        mark(x, y, b, size);
        mark(bx, by, a, size);
      };
      if (x + 1 < labels.cols) compare(l[x], l[x + 1], x + 0.5, y, x + 1, y);
      if (below != nullptr) compare(l[x], below[x], x, y + 0.5, x, y + 1);
    }
  }
  return other;
}

// Fills each layer's colour at the band pixels from the nearest pixels that show that segment
// alone, growing inwards one pixel per pass.
void CarryColours(const cv::Mat& bgr,
                  const cv::Mat& labels,
                  const cv::Mat& in_band,
                  int passes,
                  std::array<SegmentLayer, 2>* layers) {
  std::vector<cv::Point> band;
  cv::findNonZero(in_band, band);
  std::array<cv::Mat, 2> known;
  for (int k = 0; k < 2; ++k) {
    known[k] = cv::Mat::zeros(bgr.size(), CV_8U);
    for (const cv::Point& p : band) (*layers)[k].colour.at<cv::Vec3b>(p) = cv::Vec3b(0, 0, 0);
  }
  // What pixel q can tell about segment s: its image colour if it shows s alone, or a colour
  // already carried to it for s.
  const auto lookup = [&](cv::Point q, int32_t s, cv::Vec3b* colour) {
    if (!in_band.at<uint8_t>(q)) {
      if (labels.at<int32_t>(q) != s) return false;
      *colour = bgr.at<cv::Vec3b>(q);
      return true;
    }
    for (int k = 0; k < 2; ++k) {
      if (known[k].at<uint8_t>(q) && (*layers)[k].segment.at<int32_t>(q) == s) {
        *colour = (*layers)[k].colour.at<cv::Vec3b>(q);
        return true;
      }
    }
    return false;
  };
  const cv::Point steps[4] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  const cv::Rect frame(0, 0, bgr.cols, bgr.rows);
  for (int pass = 0; pass < passes; ++pass) {
    std::vector<std::pair<cv::Point, std::pair<int, cv::Vec3b>>> found;
    for (const cv::Point& p : band) {
      for (int k = 0; k < 2; ++k) {
        if (known[k].at<uint8_t>(p)) continue;
        const int32_t s = (*layers)[k].segment.at<int32_t>(p);
        if (s == kNone) continue;
        cv::Vec3i sum(0, 0, 0);
        int count = 0;
        for (const cv::Point& step : steps) {
          const cv::Point q = p + step;
          cv::Vec3b colour;
          if (frame.contains(q) && lookup(q, s, &colour)) {
            sum += cv::Vec3i(colour);
            ++count;
          }
        }
        if (count > 0) found.push_back({p, {k, cv::Vec3b(sum / count)}});
      }
    }
    if (found.empty()) break;
    for (const auto& [p, entry] : found) {
      (*layers)[entry.first].colour.at<cv::Vec3b>(p) = entry.second;
      known[entry.first].at<uint8_t>(p) = 1;
    }
  }
  // A segment seen nowhere alone (thin slivers): its observed colour.
  for (const cv::Point& p : band) {
    for (int k = 0; k < 2; ++k) {
      if (!known[k].at<uint8_t>(p) && (*layers)[k].segment.at<int32_t>(p) != kNone) {
        (*layers)[k].colour.at<cv::Vec3b>(p) = bgr.at<cv::Vec3b>(p);
      }
    }
  }
}

// Below this colour distance (0..255 levels, Euclidean over B, G, R) between the carried foreground
// and background colours, a pixel's colour says little about their mix: alpha keeps the ramp.
constexpr float kMatteMinContrast = 24.0f;

// Alpha of `colour` as a mix a * foreground + (1 - a) * background: its projection on the line from
// background to foreground, blended towards `prior` where the two are too alike to tell apart, and
// kept within `max_change` of `prior` and within [0, 1] (a textured surface can look like the
// other side; the prior says which side of the edge the pixel is on).
float MatteAlpha(
    const cv::Vec3f& colour, const cv::Vec3f& foreground, const cv::Vec3f& background, float prior, float max_change) {
  const cv::Vec3f span = foreground - background;
  const float contrast_sq = span.dot(span);
  const float trust = std::min(1.0f, contrast_sq / (kMatteMinContrast * kMatteMinContrast));
  const float projected = contrast_sq > 0 ? (colour - background).dot(span) / contrast_sq : prior;
  const float alpha = trust * projected + (1.0f - trust) * prior;
  return std::clamp(alpha, std::max(0.0f, prior - max_change), std::min(1.0f, prior + max_change));
}

// Boundary matting over the band: each pixel's alpha from its colour between the two carried
// colours, within 0.5 of the linear ramp, which it replaces where the colours differ enough to
// tell: the real silhouette is about a pixel wide, the ramp 2 * band + 1 (a fixed ramp mixes
// background into the foreground's edge pixels in every novel view), and a segment border that
// misses the silhouette by a pixel is followed. Depth follows the dominant layer.
void MatteBand(const cv::Mat& bgr,
               const cv::Mat& in_band,
               const std::vector<InversePlane>& planes,
               LayeredDepthView* view) {
  constexpr float kMaxChange = 0.5f;
  std::vector<cv::Point> band;
  cv::findNonZero(in_band, band);
  for (const cv::Point& p : band) {
    float& alpha = view->layers[0].weight.at<float>(p);
    alpha = MatteAlpha(cv::Vec3f(bgr.at<cv::Vec3b>(p)),
                       cv::Vec3f(view->layers[0].colour.at<cv::Vec3b>(p)),
                       cv::Vec3f(view->layers[1].colour.at<cv::Vec3b>(p)),
                       alpha,
                       kMaxChange);
    view->layers[1].weight.at<float>(p) = 1 - alpha;
    const int32_t dominant = view->layers[alpha >= 0.5f ? 0 : 1].segment.at<int32_t>(p);
    view->depth_m.at<float>(p) = static_cast<float>(1.0 / planes[dominant].At(p.x, p.y));
  }
}

}  // namespace

LayeredDepthView BuildTwoLayerView(ViewId id,
                                   const CameraModel& camera,
                                   const cv::Mat& bgr,
                                   const SegmentImage& segments,
                                   const cv::Mat& pixel_confidence,
                                   const TwoLayerOptions& options) {
  const cv::Size size(camera.width, camera.height);
  PX_CHECK(bgr.type() == CV_8UC3 && bgr.size() == size && segments.labels.type() == CV_32S &&
           segments.labels.size() == size && pixel_confidence.type() == CV_32F && pixel_confidence.size() == size);
  PX_CHECK(options.edge_inverse_depth_m > 0 && options.min_inverse_depth_m > 0 && options.band_radius_px >= 1);
  const cv::Mat& labels = segments.labels;
  const int num_segments = static_cast<int>(segments.planes.size());
  LayeredDepthView view;
  view.id = id;
  view.camera = camera;
  view.confidence = pixel_confidence.clone();

  // Planes that stay in front of the camera over their segment and its band.
  std::vector<InversePlane> planes = segments.planes;
  {
    std::vector<cv::Rect> boxes(num_segments);
    std::vector<cv::Point2d> sums(num_segments, cv::Point2d(0, 0));
    std::vector<int> counts(num_segments, 0);
    for (int y = 0; y < size.height; ++y) {
      const int32_t* l = labels.ptr<int32_t>(y);
      for (int x = 0; x < size.width; ++x) {
        const int32_t s = l[x];
        PX_CHECK(s >= 0 && s < num_segments);
        boxes[s] = counts[s] == 0 ? cv::Rect(x, y, 1, 1) : (boxes[s] | cv::Rect(x, y, 1, 1));
        sums[s] += cv::Point2d(x, y);
        ++counts[s];
      }
    }
    const int r = options.band_radius_px + 1;  // a partner reaches one pixel past the band
    for (int s = 0; s < num_segments; ++s) {
      if (counts[s] == 0) continue;
      const cv::Rect grown = cv::Rect(boxes[s].x - r, boxes[s].y - r, boxes[s].width + 2 * r, boxes[s].height + 2 * r) &
                             cv::Rect(0, 0, size.width, size.height);
      KeepPositive(grown, sums[s] / counts[s], options.min_inverse_depth_m, &planes[s]);
    }
  }

  // The nearest depth-edge pixel of every pixel, and how far it is.
  const cv::Mat across = FindDepthEdges(labels, planes, options.edge_inverse_depth_m);
  cv::Mat not_edge = across == kNone;
  cv::Mat distance, nearest_label;
  cv::distanceTransform(not_edge, distance, nearest_label, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
  std::vector<cv::Point> edge_of_label;  // distance-transform label -> its edge pixel
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      if (not_edge.at<uint8_t>(y, x)) continue;
      const int label = nearest_label.at<int>(y, x);
      if (label >= static_cast<int>(edge_of_label.size())) edge_of_label.resize(label + 1, cv::Point(-1, -1));
      edge_of_label[label] = cv::Point(x, y);
    }
  }

  for (SegmentLayer& layer : view.layers) {
    layer.colour = bgr.clone();
    layer.weight = cv::Mat::zeros(size, CV_32F);
    layer.segment = cv::Mat(size, CV_32S, cv::Scalar(kNone));
  }
  view.layers[1].colour.setTo(cv::Scalar(0, 0, 0));
  view.depth_m.create(size, CV_32F);
  cv::Mat in_band = cv::Mat::zeros(size, CV_8U);
  const double band = options.band_radius_px;
  for (int y = 0; y < size.height; ++y) {
    const int32_t* l = labels.ptr<int32_t>(y);
    const float* d = distance.ptr<float>(y);
    float* z = view.depth_m.ptr<float>(y);
    for (int x = 0; x < size.width; ++x) {
      const int32_t own = l[x];
      int32_t partner = kNone;
      if (d[x] < band && !edge_of_label.empty()) {
        const int label = nearest_label.at<int>(y, x);
        const cv::Point e = label < static_cast<int>(edge_of_label.size()) ? edge_of_label[label] : cv::Point(-1, -1);
        if (e.x >= 0) {
          const int32_t e_own = labels.at<int32_t>(e), e_across = across.at<int32_t>(e);
          if (own == e_own)
            partner = e_across;
          else if (own == e_across)
            partner = e_own;
        }
      }
      const double u_own = planes[own].At(x, y);
      if (partner == kNone) {
        view.layers[0].segment.at<int32_t>(y, x) = own;
        view.layers[0].weight.at<float>(y, x) = 1;
        z[x] = static_cast<float>(1.0 / u_own);
        continue;
      }
      // Signed distance from the edge, positive on the foreground side; alpha ramps linearly
      // across the band's 2 * band pixels.
      const double u_partner = planes[partner].At(x, y);
      const bool own_in_front = u_own >= u_partner;
      const double signed_px = (own_in_front ? 1 : -1) * (d[x] + 0.5);
      const auto alpha = static_cast<float>(std::clamp(0.5 + signed_px / (2 * band + 1), 0.0, 1.0));
      const int32_t front = own_in_front ? own : partner, back = own_in_front ? partner : own;
      view.layers[0].segment.at<int32_t>(y, x) = front;
      view.layers[0].weight.at<float>(y, x) = alpha;
      view.layers[1].segment.at<int32_t>(y, x) = back;
      view.layers[1].weight.at<float>(y, x) = 1 - alpha;
      in_band.at<uint8_t>(y, x) = 1;
      z[x] = static_cast<float>(1.0 / (alpha >= 0.5f ? planes[front].At(x, y) : planes[back].At(x, y)));
    }
  }
  CarryColours(bgr, labels, in_band, 2 * options.band_radius_px + 2, &view.layers);  // across the whole band
  MatteBand(bgr, in_band, planes, &view);

  // Segments with their bounding boxes over both layers.
  view.segments.resize(num_segments);
  std::vector<char> seen(num_segments, 0);
  for (int k = 0; k < 2; ++k) {
    for (int y = 0; y < size.height; ++y) {
      const int32_t* s = view.layers[k].segment.ptr<int32_t>(y);
      const float* w = view.layers[k].weight.ptr<float>(y);
      for (int x = 0; x < size.width; ++x) {
        if (s[x] == kNone || w[x] <= 0) continue;
        DepthSegment& segment = view.segments[s[x]];
        segment.bbox = seen[s[x]] ? (segment.bbox | cv::Rect(x, y, 1, 1)) : cv::Rect(x, y, 1, 1);
        seen[s[x]] = 1;
        ++segment.num_pixels;
      }
    }
  }
  for (int s = 0; s < num_segments; ++s) {
    DepthSegment& segment = view.segments[s];
    segment.inv_depth_a = planes[s].a;
    segment.inv_depth_b = planes[s].b;
    segment.inv_depth_c = planes[s].c;
    segment.confidence =
        s < static_cast<int>(segments.confidence.size()) ? std::clamp(segments.confidence[s], 0.0f, 1.0f) : 0.0f;
  }
  return view;
}

int CountBoundaryPixels(const LayeredDepthView& view) { return cv::countNonZero(view.layers[1].weight > 0); }

}  // namespace px::depth
