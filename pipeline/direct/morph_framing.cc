#include "pipeline/direct/morph_framing.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "pipeline/core/order_statistics.h"

namespace px::direct {

namespace {

// Below this end zoom a push-in is not worth showing: the morph keeps the whole frame.
constexpr double kMinPushIn = 1.04;
// Samples per side of the grid whose median flow carries the subjects' box.
constexpr int kFlowSamples = 7;

// The widest crop of the output's aspect inside the morph's image, as (width, height).
cv::Size2d WidestCrop(const CameraPath& path, cv::Size image) {
  const double aspect = static_cast<double>(path.width) / std::max(1, path.height);
  const double width = std::min<double>(image.width, image.height * aspect);
  return {width, width / aspect};
}

double ZoomAt(const CameraPath& path, double t) {
  return std::max(1.0, path.FocalAt(t) / path.keyframes.front().focal_px);
}

// The box with every side moved in by `margin` (a box too small for it stays centred, empty).
cv::Rect2d Inset(const cv::Rect2d& box, double margin) {
  const double w = std::max(0.0, box.width - 2 * margin), h = std::max(0.0, box.height - 2 * margin);
  return {box.x + 0.5 * (box.width - w), box.y + 0.5 * (box.height - h), w, h};
}

bool Contains(const cv::Rect2d& outer, const cv::Rect2d& inner) {
  return inner.x >= outer.x && inner.y >= outer.y && inner.x + inner.width <= outer.x + outer.width &&
         inner.y + inner.height <= outer.y + outer.height;
}

}  // namespace

cv::Rect2d MorphSubjectsBoxAt(const CameraPath& path, const ViewMorph& morph, double t) {
  cv::Rect2d box;
  bool any = false;
  for (const Subject& subject : path.subjects) {
    if (path.source_views.empty() || subject.view != path.source_views[0]) continue;
    box = any ? (box | subject.box_px) : subject.box_px;
    any = true;
  }
  if (!any) return {};
  // The median flow inside the box: a face's own motion, not the background at its corners.
  std::vector<double> dx, dy;
  for (int j = 0; j < kFlowSamples; ++j) {
    for (int i = 0; i < kFlowSamples; ++i) {
      const cv::Point2d p(box.x + (i + 0.5) * box.width / kFlowSamples, box.y + (j + 0.5) * box.height / kFlowSamples);
      const cv::Point2d q = morph.TrackFromA(p, 1.0);
      dx.push_back(q.x - p.x);
      dy.push_back(q.y - p.y);
    }
  }
  const double s = std::clamp(t, 0.0, 1.0);
  return {box.x + s * Median(dx), box.y + s * Median(dy), box.width, box.height};
}

namespace {

// `centre` moved as little as brings `box` inside a window of `size` centred there, `margin`
// from its edges (to the box's centre where the window is too small for it).
cv::Point2d FramingCentre(cv::Point2d centre, const cv::Rect2d& box, cv::Size2d size, double margin) {
  const double lo_x = box.x + box.width + margin - 0.5 * size.width, hi_x = box.x - margin + 0.5 * size.width;
  const double lo_y = box.y + box.height + margin - 0.5 * size.height, hi_y = box.y - margin + 0.5 * size.height;
  centre.x = lo_x <= hi_x ? std::clamp(centre.x, lo_x, hi_x) : box.x + 0.5 * box.width;
  centre.y = lo_y <= hi_y ? std::clamp(centre.y, lo_y, hi_y) : box.y + 0.5 * box.height;
  return centre;
}

}  // namespace

cv::Rect2d MorphWindowAt(const CameraPath& path, const ViewMorph& morph, double t, double margin_fraction) {
  const cv::Size image = morph.size();
  const cv::Size2d crop = WidestCrop(path, image);
  const double zoom = ZoomAt(path, t);
  const double end_zoom = ZoomAt(path, 1.0);
  const cv::Size2d size(crop.width / zoom, crop.height / zoom);
  cv::Point2d centre(0.5 * image.width, 0.5 * image.height);
  const cv::Rect2d box = MorphSubjectsBoxAt(path, morph, t);
  if (box.area() > 0) {
    // From the least turn that frames the subjects (a portrait cut from a landscape morph) to
    // their lower half's centre, as far as the zoom has come.
    const double margin = margin_fraction * size.width;
    const cv::Point2d from = FramingCentre(centre, box, size, margin);
    const cv::Point2d target(box.x + 0.5 * box.width, box.y + 0.75 * box.height);
    const double reached = end_zoom > 1 ? (zoom - 1) / (end_zoom - 1) : 0.0;
    centre = from + reached * (target - from);
  }
  const double x = std::clamp(centre.x - 0.5 * size.width, 0.0, image.width - size.width);
  const double y = std::clamp(centre.y - 0.5 * size.height, 0.0, image.height - size.height);
  return {x, y, size.width, size.height};
}

double PlanMorphPushIn(const ViewMorph& morph, const DirectOptions& options, CameraPath* path) {
  CameraKeyframe& first = path->keyframes.front();
  CameraKeyframe& last = path->keyframes.back();
  last.focal_px = first.focal_px;
  const cv::Rect2d end_box = MorphSubjectsBoxAt(*path, morph, 1.0);
  if (end_box.area() <= 0) return 1.0;
  const cv::Size2d crop = WidestCrop(*path, morph.size());
  const double margin = options.framing_margin * crop.width;
  // The lower half's centre is centred: the box reaches 3/4 of its height above it.
  double zoom = std::min(
      {options.zoom_in, crop.width / (end_box.width + 2 * margin), crop.height / (1.5 * end_box.height + 2 * margin)});
  // Narrow the push-in until every frame keeps the subjects inside with the margin.
  for (int round = 0; round < 30 && zoom >= kMinPushIn; ++round) {
    last.focal_px = zoom * first.focal_px;
    bool inside = true;
    for (int i = 0; i < path->NumFrames() && inside; ++i) {
      const double t = path->FrameTime(i);
      const cv::Rect2d window = MorphWindowAt(*path, morph, t, options.framing_margin);
      inside = Contains(Inset(window, margin / ZoomAt(*path, t)), MorphSubjectsBoxAt(*path, morph, t));
    }
    if (inside) return zoom;
    zoom = 1 + 0.85 * (zoom - 1);
  }
  last.focal_px = first.focal_px;
  return 1.0;
}

cv::Mat CutMorphFrame(
    const cv::Mat& image, const CameraPath& path, const ViewMorph& morph, double t, double margin_fraction) {
  cv::Rect2d window = MorphWindowAt(path, morph, t, margin_fraction);
  cv::Mat source = image;
  // Shrink first where the window is much larger than the frame, so that the bilinear cut
  // below does not alias.
  const double shrink = std::min(window.width / path.width, window.height / path.height);
  if (shrink > 1.5) {
    cv::resize(image, source, cv::Size(), 1 / shrink, 1 / shrink, cv::INTER_AREA);
    const double sx = static_cast<double>(source.cols) / image.cols, sy = static_cast<double>(source.rows) / image.rows;
    window = {window.x * sx, window.y * sy, window.width * sx, window.height * sy};
  }
  // Output pixel centres mapped into the window (pixel centres at integer coordinates).
  const double sx = window.width / path.width, sy = window.height / path.height;
  const cv::Matx23d frame_to_source(sx, 0, window.x + 0.5 * sx - 0.5, 0, sy, window.y + 0.5 * sy - 0.5);
  cv::Mat out;
  cv::warpAffine(source,
                 out,
                 frame_to_source,
                 cv::Size(path.width, path.height),
                 cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                 cv::BORDER_REPLICATE);
  return out;
}

}  // namespace px::direct
