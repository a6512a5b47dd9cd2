#include "pipeline/run/repeated_frames.h"

namespace px {

RepeatedFrames::RepeatedFrames(const CameraPath& path, size_t budget_bytes) : path_(path), budget_bytes_(budget_bytes) {
  for (int i = 0; i < path.NumFrames(); ++i) ++by_time_[path.FrameTime(i)].uses_left;
}

std::optional<DrawnFrame> RepeatedFrames::Take(int index) {
  auto it = by_time_.find(path_.FrameTime(index));
  if (it == by_time_.end()) return std::nullopt;
  --it->second.uses_left;
  std::optional<DrawnFrame> frame = it->second.frame;
  if (it->second.uses_left <= 0 && it->second.frame) {  // its last showing: let it go
    kept_bytes_ -= it->second.frame->bgr.total() * it->second.frame->bgr.elemSize();
    it->second.frame.reset();
  }
  if (frame) ++reused_;
  return frame;
}

void RepeatedFrames::Keep(int index, const cv::Mat& bgr, const CoverageReport& holes) {
  auto it = by_time_.find(path_.FrameTime(index));
  if (it == by_time_.end() || it->second.uses_left <= 0 || it->second.frame) return;
  const size_t bytes = bgr.total() * bgr.elemSize();
  if (kept_bytes_ + bytes > budget_bytes_) return;
  it->second.frame = DrawnFrame{bgr.clone(), holes};
  kept_bytes_ += bytes;
}

}  // namespace px
