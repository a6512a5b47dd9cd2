// Hands rendered frames to a FrameSink on its own thread, so that encoding frame i overlaps
// rendering frame i + 1 (the encoder's colour conversion and x264's submit would otherwise leave
// the render's cores idle in turn). Frames keep their order; at most `capacity` wait in the
// queue, so a slow sink holds the renderer back instead of piling frames up in memory. The first
// error of the sink is returned by the next Consume and by Finish, and the frames after it are
// dropped.
#pragma once

#include <condition_variable>
#include <deque>
#include <mutex>
#include <opencv2/core.hpp>
#include <thread>
#include <utility>

#include "pipeline/core/status.h"
#include "pipeline/run/pipeline.h"

namespace px {

class OverlappedFrameSink final : public FrameSink {
 public:
  // `sink` must outlive this object and is called from one worker thread only. capacity >= 1.
  OverlappedFrameSink(FrameSink* sink, int capacity);
  // Finishes (waits for the queued frames) if Finish was not called.
  ~OverlappedFrameSink() override;
  OverlappedFrameSink(const OverlappedFrameSink&) = delete;
  OverlappedFrameSink& operator=(const OverlappedFrameSink&) = delete;

  // Queues the frame (the Mat's pixels are shared, not copied: the caller must not write to
  // them afterwards) and returns at once, or after a queued frame left when the queue is full.
  // Returns the sink's first error so far.
  Status Consume(int index, const cv::Mat& bgr) override;
  // Waits until every queued frame was consumed and stops the worker; the sink's first error.
  Status Finish();

  // After Finish: milliseconds the sink spent consuming (on the worker), and the caller spent
  // waiting for it (a full queue, and Finish).
  double sink_ms() const { return sink_ms_; }
  double wait_ms() const { return wait_ms_; }

 private:
  void Run();

  FrameSink* sink_;
  const size_t capacity_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::pair<int, cv::Mat>> queue_;
  bool closing_ = false;
  Status error_;
  double sink_ms_ = 0;  // written by the worker under mutex_
  double wait_ms_ = 0;  // the caller's thread only
  std::thread worker_;
};

}  // namespace px
