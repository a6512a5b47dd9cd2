#include "pipeline/depth/free_space.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "pipeline/core/check.h"
#include "pipeline/depth/superpixels.h"
#include "pipeline/depth/view_to_view.h"

namespace px::depth {
namespace {

// Another view as the reference's points land in it.
struct OtherView {
  ViewToView projection;
  const cv::Mat* depth_m = nullptr;
  const cv::Mat* image = nullptr;  // CV_8UC3
  double see_through_inverse = 0;  // 1/m
  double confirm_inverse = 0;      // 1/m
};

// What one other view says about a segment's pixels under one plane.
struct Verdict {
  int projected = 0;  // pixels landing on known depth in that view
  int seen_through = 0;
  int hidden = 0;      // behind what that view sees: it can neither confirm nor contradict them
  int confirmed = 0;   // the same depth there, and the same colour
  int mismatched = 0;  // the same depth there, another colour
};

// Colours closer than this in every channel are the same surface's (noise, resampling, the
// views' remaining exposure differences); a moved subject over the background is not.
constexpr int kSameColourLevels = 20;

bool SameColour(const cv::Vec3b& a, const cv::Vec3b& b) {
  for (int c = 0; c < 3; ++c) {
    if (std::abs(static_cast<int>(a[c]) - static_cast<int>(b[c])) > kSameColourLevels) return false;
  }
  return true;
}

Verdict Judge(const View& ref,
              const OtherView& other,
              const std::vector<cv::Point>& pixels,
              const InversePlane& plane) {
  Verdict verdict;
  const cv::Mat& seen_depth = *other.depth_m;
  for (const cv::Point& p : pixels) {
    const double inverse = plane.At(p.x, p.y);
    if (!(inverse > 0)) continue;
    int u = 0, v = 0;
    double z_other = 0;
    if (!other.projection.Project(p.x, p.y, 1.0 / inverse, &u, &v, &z_other)) continue;
    const float seen = seen_depth.at<float>(v, u);
    if (!(seen > 0)) continue;
    ++verdict.projected;
    const double nearer_by = 1.0 / z_other - 1.0 / seen;  // > 0: our point is in front of what it sees
    if (std::abs(nearer_by) <= other.confirm_inverse) {
      const bool same = SameColour(ref.image.at<cv::Vec3b>(p), other.image->at<cv::Vec3b>(v, u));
      ++(same ? verdict.confirmed : verdict.mismatched);
    } else if (nearer_by > other.see_through_inverse) {
      ++verdict.seen_through;
    } else if (nearer_by < 0) {
      ++verdict.hidden;
    }
  }
  return verdict;
}

// Judged views: those that see at least a quarter of the segment's pixels.
bool IsJudged(const Verdict& verdict, size_t num_pixels) {
  return 4 * verdict.projected >= static_cast<int>(num_pixels);
}

bool Contradicted(const std::vector<Verdict>& verdicts, size_t num_pixels, double min_fraction) {
  int judged = 0, through = 0;
  for (const Verdict& v : verdicts) {
    if (!IsJudged(v, num_pixels)) continue;
    ++judged;
    if (v.seen_through >= min_fraction * v.projected) ++through;
  }
  return judged > 0 && 2 * through > judged;
}

// Mean over the views that see at least a quarter of the segment's pixels unhidden: the share
// of those pixels confirmed, less the shares of another colour and seen through. 0 where every
// view has something nearer in front of the plane: nothing there speaks for or against it.
double Agreement(const std::vector<Verdict>& verdicts, size_t num_pixels) {
  double sum = 0;
  int judged = 0;
  for (const Verdict& v : verdicts) {
    const int visible = v.projected - v.hidden;
    if (4 * visible < static_cast<int>(num_pixels)) continue;
    ++judged;
    sum += static_cast<double>(v.confirmed - v.mismatched - v.seen_through) / visible;
  }
  return judged > 0 ? sum / judged : 0.0;
}

}  // namespace

FreeSpaceStats ReplaneSeenThroughSegments(const std::vector<View>& views,
                                          const std::vector<cv::Mat>& depth_m,
                                          int reference,
                                          const std::vector<int>& others,
                                          const FreeSpaceOptions& options,
                                          SegmentImage* segments) {
  PX_CHECK(segments != nullptr && segments->labels.type() == CV_32S);
  PX_CHECK(reference >= 0 && reference < static_cast<int>(views.size()) && depth_m.size() == views.size());
  PX_CHECK(segments->labels.cols == views[reference].camera.width &&
           segments->labels.rows == views[reference].camera.height);
  PX_CHECK(segments->confidence.size() == segments->planes.size());
  PX_CHECK(options.see_through_px > 0 && options.confirm_px > 0);
  PX_CHECK(options.min_seen_through_fraction > 0 && options.min_seen_through_fraction <= 1);
  FreeSpaceStats stats;
  const View& ref = views[reference];
  std::vector<OtherView> judges;
  for (int k : others) {
    if (k == reference || depth_m[k].empty()) continue;
    const ViewToView projection(ref, views[k]);
    if (!(projection.focal_baseline() > 0)) continue;
    judges.push_back({projection,
                      &depth_m[k],
                      &views[k].image,
                      options.see_through_px / projection.focal_baseline(),
                      options.confirm_px / projection.focal_baseline()});
  }
  if (judges.empty()) return stats;

  const int count = static_cast<int>(segments->planes.size());
  std::vector<std::vector<cv::Point>> pixels(count);
  for (int y = 0; y < segments->labels.rows; ++y) {
    const int* row = segments->labels.ptr<int>(y);
    for (int x = 0; x < segments->labels.cols; ++x) {
      PX_CHECK(row[x] >= 0 && row[x] < count);
      pixels[row[x]].emplace_back(x, y);
    }
  }
  const auto verdicts_of = [&](int s, const InversePlane& plane) {
    std::vector<Verdict> verdicts;
    for (const OtherView& judge : judges) verdicts.push_back(Judge(ref, judge, pixels[s], plane));
    return verdicts;
  };
  std::vector<char> contradicted(count, 0);
  cv::parallel_for_(cv::Range(0, count), [&](const cv::Range& range) {
    for (int s = range.start; s < range.end; ++s) {
      if (pixels[s].empty() || !(segments->confidence[s] < options.max_confidence)) continue;
      contradicted[s] =
          Contradicted(verdicts_of(s, segments->planes[s]), pixels[s].size(), options.min_seen_through_fraction);
    }
  });
  stats.contradicted = static_cast<int>(std::count(contradicted.begin(), contradicted.end(), 1));
  if (stats.contradicted == 0) return stats;

  // Contradicted segments take planes from the outside in: each sweep settles those with a
  // settled neighbour, whose plane (or a re-planed neighbour's) is then a candidate for the next.
  const std::vector<std::vector<int>> adjacent = AdjacentLabels(segments->labels, count);
  std::vector<char> settled(count), usable(count);
  for (int s = 0; s < count; ++s) settled[s] = usable[s] = !contradicted[s];
  for (int sweep = 0; sweep < count; ++sweep) {
    std::vector<int> pending;
    for (int s = 0; s < count; ++s) {
      if (settled[s]) continue;
      if (std::any_of(adjacent[s].begin(), adjacent[s].end(), [&](int t) { return settled[t] != 0; }))
        pending.push_back(s);
    }
    if (pending.empty()) break;
    std::vector<std::pair<int, int>> chosen(pending.size(), {-1, -1});  // (segment, plane donor)
    cv::parallel_for_(cv::Range(0, static_cast<int>(pending.size())), [&](const cv::Range& range) {
      for (int i = range.start; i < range.end; ++i) {
        const int s = pending[i];
        const size_t n = pixels[s].size();
        // A candidate must not be refuted more than confirmed: a subject that moved between the
        // shots is seen through too, but no neighbour's plane carries its colour into the others,
        // and it keeps its own plane (the consistent blend draws it from one view).
        double best = std::max(-1e-9, Agreement(verdicts_of(s, segments->planes[s]), n));
        chosen[i] = {s, -1};
        for (int t : adjacent[s]) {
          if (!usable[t]) continue;
          const std::vector<Verdict> verdicts = verdicts_of(s, segments->planes[t]);
          if (Contradicted(verdicts, n, options.min_seen_through_fraction)) continue;
          const double agreement = Agreement(verdicts, n);
          if (agreement > best) {
            best = agreement;
            chosen[i].second = t;
          }
        }
      }
    });
    for (const auto& [s, donor] : chosen) {
      settled[s] = 1;
      if (donor < 0) continue;
      segments->planes[s] = segments->planes[donor];
      usable[s] = 1;
      ++stats.replaned;
    }
  }
  return stats;
}

}  // namespace px::depth
