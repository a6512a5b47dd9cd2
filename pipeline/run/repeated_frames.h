// Frames of a clip that show the same place of the path (a held last frame, a loop's way back,
// a boomerang's return) are drawn once and reused: a drawn frame is kept, by its path time,
// only while a later frame still needs it, and only within a memory budget (past it the frame
// is simply drawn again).
#pragma once

#include <cstddef>
#include <map>
#include <opencv2/core.hpp>
#include <optional>

#include "pipeline/core/coverage_report.h"
#include "pipeline/direct/camera_path.h"

namespace px {

struct DrawnFrame {
  cv::Mat bgr;
  CoverageReport holes;
};

class RepeatedFrames {
 public:
  RepeatedFrames(const CameraPath& path, size_t budget_bytes);
  // Frame `index`'s earlier drawing, if one was kept.
  std::optional<DrawnFrame> Take(int index);
  // Keeps frame `index`'s drawing (a copy) when a later frame shows the same place.
  void Keep(int index, const cv::Mat& bgr, const CoverageReport& holes);
  int reused() const { return reused_; }

 private:
  struct Entry {
    int uses_left = 0;  // frames after the current one that show this place
    std::optional<DrawnFrame> frame;
  };
  const CameraPath& path_;
  size_t budget_bytes_;
  size_t kept_bytes_ = 0;
  std::map<double, Entry> by_time_;
  int reused_ = 0;
};

}  // namespace px
