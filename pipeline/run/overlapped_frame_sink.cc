#include "pipeline/run/overlapped_frame_sink.h"

#include <algorithm>
#include <exception>
#include <string>

#include "pipeline/core/stage_clock.h"

namespace px {

OverlappedFrameSink::OverlappedFrameSink(FrameSink* sink, int capacity)
    : sink_(sink), capacity_(static_cast<size_t>(std::max(1, capacity))), worker_([this] { Run(); }) {}

OverlappedFrameSink::~OverlappedFrameSink() { (void)Finish(); }

Status OverlappedFrameSink::Consume(int index, const cv::Mat& bgr) {
  const StageClock::time_point start = StageClock::now();
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [&] { return queue_.size() < capacity_ || !error_.ok() || closing_; });
  wait_ms_ += MsSince(start);
  if (!error_.ok()) return error_;
  if (closing_) return FailedPreconditionError("frame sink: frame " + std::to_string(index) + " after Finish");
  queue_.emplace_back(index, bgr);
  changed_.notify_all();
  return OkStatus();
}

Status OverlappedFrameSink::Finish() {
  const StageClock::time_point start = StageClock::now();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closing_ = true;
    changed_.notify_all();
  }
  if (worker_.joinable()) worker_.join();
  wait_ms_ += MsSince(start);
  std::lock_guard<std::mutex> lock(mutex_);
  return error_;
}

void OverlappedFrameSink::Run() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    changed_.wait(lock, [&] { return !queue_.empty() || closing_; });
    if (queue_.empty()) return;  // closing, and every frame consumed
    std::pair<int, cv::Mat> frame = std::move(queue_.front());
    queue_.pop_front();
    changed_.notify_all();       // room in the queue
    if (!error_.ok()) continue;  // drop the frames after an error
    lock.unlock();
    const StageClock::time_point start = StageClock::now();
    Status consumed;
    try {
      consumed = sink_->Consume(frame.first, frame.second);
    } catch (const std::exception& e) {  // on this thread an escaping exception would end the process
      consumed = InternalError("frame sink: frame " + std::to_string(frame.first) + ": " + e.what());
    }
    const double ms = MsSince(start);
    frame.second.release();
    lock.lock();
    sink_ms_ += ms;
    if (!consumed.ok()) {
      error_ = std::move(consumed);
      changed_.notify_all();
    }
  }
}

}  // namespace px
