#include "pipeline/run/overlapped_frame_sink.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

namespace px {
namespace {

// Records what it got and on which thread; fails at frame `fail_at` (-1: never); can hold each
// frame until released, to fill the queue.
class RecordingSink : public FrameSink {
 public:
  Status Consume(int index, const cv::Mat& bgr) override {
    while (hold.load()) std::this_thread::yield();
    threads.push_back(std::this_thread::get_id());
    indices.push_back(index);
    values.push_back(bgr.at<uint8_t>(0, 0));
    if (index == fail_at) return InternalError("disk full at frame " + std::to_string(index));
    return OkStatus();
  }
  std::atomic<bool> hold{false};
  int fail_at = -1;
  std::vector<std::thread::id> threads;
  std::vector<int> indices;
  std::vector<int> values;
};

cv::Mat Frame(int value) { return cv::Mat(4, 4, CV_8U, cv::Scalar(value)); }

TEST(OverlappedFrameSinkTest, ConsumesEveryFrameInOrderOnItsOwnThread) {
  RecordingSink sink;
  OverlappedFrameSink overlapped(&sink, 2);
  for (int i = 0; i < 20; ++i) ASSERT_TRUE(overlapped.Consume(i, Frame(i)).ok());
  ASSERT_TRUE(overlapped.Finish().ok());
  ASSERT_EQ(sink.indices.size(), 20u);
  for (int i = 0; i < 20; ++i) {
    EXPECT_EQ(sink.indices[i], i);
    EXPECT_EQ(sink.values[i], i);  // the frame's pixels, not a later frame's
    EXPECT_NE(sink.threads[i], std::this_thread::get_id());
  }
  EXPECT_GE(overlapped.sink_ms(), 0.0);
}

TEST(OverlappedFrameSinkTest, AFullQueueHoldsTheCallerBack) {
  RecordingSink sink;
  sink.hold = true;
  OverlappedFrameSink overlapped(&sink, 2);
  // The worker takes frame 0 and waits inside the sink; frames 1 and 2 fill the queue.
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(overlapped.Consume(i, Frame(i)).ok());
  std::atomic<bool> queued{false};
  std::thread caller([&] {
    EXPECT_TRUE(overlapped.Consume(3, Frame(3)).ok());
    queued = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_FALSE(queued.load());  // blocked: no room
  sink.hold = false;
  caller.join();
  EXPECT_TRUE(queued.load());
  ASSERT_TRUE(overlapped.Finish().ok());
  EXPECT_EQ(sink.indices, (std::vector<int>{0, 1, 2, 3}));
  EXPECT_GT(overlapped.wait_ms(), 0.0);
}

TEST(OverlappedFrameSinkTest, TheSinksErrorStopsTheClipAndIsReturned) {
  RecordingSink sink;
  sink.fail_at = 3;
  OverlappedFrameSink overlapped(&sink, 2);
  Status status;
  int i = 0;
  for (; i < 50 && status.ok(); ++i) status = overlapped.Consume(i, Frame(i));
  const Status finished = overlapped.Finish();
  EXPECT_FALSE(finished.ok());
  EXPECT_NE(finished.message().find("disk full at frame 3"), std::string::npos) << finished.ToString();
  // Frames after the failing one are dropped, and the caller heard of it within the queue's length.
  EXPECT_EQ(sink.indices.back(), 3);
  EXPECT_LE(i, 3 + 2 + 2);
  EXPECT_FALSE(overlapped.Consume(99, Frame(99)).ok());
}

class ThrowingSink : public FrameSink {
 public:
  Status Consume(int index, const cv::Mat&) override {
    if (index == 1) throw std::runtime_error("codec exploded");
    return OkStatus();
  }
};

TEST(OverlappedFrameSinkTest, AnExceptionInTheSinkBecomesAnError) {
  ThrowingSink sink;
  OverlappedFrameSink overlapped(&sink, 2);
  for (int i = 0; i < 3; ++i) (void)overlapped.Consume(i, Frame(i));
  const Status finished = overlapped.Finish();
  EXPECT_FALSE(finished.ok());
  EXPECT_NE(finished.message().find("codec exploded"), std::string::npos) << finished.ToString();
}

TEST(OverlappedFrameSinkTest, DestroyingWithoutFinishConsumesWhatWasQueued) {
  RecordingSink sink;
  {
    OverlappedFrameSink overlapped(&sink, 3);
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(overlapped.Consume(i, Frame(i)).ok());
  }
  EXPECT_EQ(sink.indices, (std::vector<int>{0, 1, 2}));
}

}  // namespace
}  // namespace px
