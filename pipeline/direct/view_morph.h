// Two-view morphing (paper 4.5): with only two views, or no depth worth trusting, the clip morphs
// from one view to the other along dense correspondences, interpolated linearly. Correspondences
// tolerate small scene motion through a *soft* epipolar constraint:
//   1. dense optical flow both ways (OpenCV's DIS flow, on a working copy at most 640 px wide);
//   2. the fundamental matrix from flow samples that agree forwards and backwards (RANSAC);
//   3. each flow vector is pulled onto its epipolar line with weight exp(-e^2 / 2 sigma^2), e its
//      distance from the line: a match off the line by noise (e << sigma) snaps onto it, while one
//      far off it (a moving hand, e >> sigma) keeps its own motion. The paper's stereo [34] puts
//      the same soft penalty into the matching cost; here it corrects a free flow afterwards.
// Frames (after Baker et al.'s flow interpolation): the flow is forward-splatted to time t (a
// pixel seen in both views wins over one that the other view does not see), holes are filled
// from their neighbours, and both views are sampled backwards and blended by (1 - t, t), each
// only where it sees the pixel.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "pipeline/core/status.h"

namespace px::direct {

struct MorphOptions {
  int working_width_px = 640;      // flow is computed at most this wide, [64, 4096]
  double epipolar_sigma_px = 2.0;  // soft constraint scale at full size, (0, 50]
  double consistency_px = 1.5;     // forward-backward disagreement still counted as one match, (0, 20]
  Status Validate() const;
};

struct MorphReport {
  double consistent_fraction = 0;     // pixels whose flow agrees forwards and backwards
  double textured_fraction = 0;       // pixels with texture enough to measure flow on (the rest is interpolated)
  double textured_consistent = 0;     // of those, the share whose flow agrees forwards and backwards
  bool epipolar = false;              // a fundamental matrix was found (else flow is used as is)
  int fundamental_samples = 0;        // flow samples offered to RANSAC
  double fundamental_inliers = 0;     // their fraction within 1.5 px of the epipolar lines
  double median_epipolar_px = 0;      // median distance of consistent flow from its line, before
  double moving_fraction = 0;         // consistent pixels more than 3 sigma off their line (scene motion)
  double mean_abs_diff_unwarped = 0;  // mean |a - b| over the frame (grey levels): what no morph scores
  double mean_abs_diff_warped = 0;    // mean |a - b(p + flow)| over consistent pixels: the flow's fit
  double ms = 0;                      // to compute it all
};

class ViewMorph {
 public:
  // `a` and `b`: CV_8UC3 of one size. Fails naming the mismatch.
  static StatusOr<std::unique_ptr<ViewMorph>> Create(const cv::Mat& a, const cv::Mat& b, const MorphOptions& options);

  // The morph at t in [0, 1] (0 = a, 1 = b), CV_8UC3 of a's size.
  cv::Mat FrameAt(double t) const;
  // Where a pixel of `a` is at time t (for checks: a face's box moves along with it).
  cv::Point2d TrackFromA(const cv::Point2d& pixel_in_a, double t) const;

  const MorphReport& report() const { return report_; }
  cv::Size size() const { return a_.size(); }

 private:
  ViewMorph() = default;

  cv::Mat a_, b_;              // CV_8UC3
  cv::Mat flow_ab_, flow_ba_;  // CV_32FC2 at full size, soft-epipolar corrected
  cv::Mat seen_ab_, seen_ba_;  // CV_8U: 255 where the pixel's flow agrees forwards and backwards
  MorphReport report_;
};

}  // namespace px::direct
