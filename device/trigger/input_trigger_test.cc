// The trigger's event handling, driven by real input_event records through a FIFO, with the
// loop's calls (Service) made by hand so every step is deterministic.
#include "device/trigger/input_trigger.h"

#include <gtest/gtest.h>
#include <poll.h>
#include <sys/stat.h>

#include "device/trigger/input_trigger_test_util.h"
#include "tests/testing/temp_dir.h"

namespace px::device {
namespace {

using namespace std::chrono_literals;
using testing::Concat;
using testing::Event;
using testing::EventWriter;
using testing::Key;

class InputTriggerTest : public px::testing::TempDirTest {
 protected:
  void SetUp() override {
    fifo_ = dir() / "event0";
    ASSERT_EQ(::mkfifo(fifo_.c_str(), 0600), 0);
    InputTriggerOptions options;
    options.device = fifo_;
    options.key_code = KEY_CAMERA;
    options.debounce = 50ms;
    options.retry = 1000ms;
    trigger_ = std::make_unique<InputTrigger>(options);
    now_ = std::chrono::steady_clock::now();
    // Due at once: the first Service opens the device.
    ASSERT_TRUE(trigger_->Deadline().has_value());
    EXPECT_EQ(trigger_->Service(now_, 0), 0);
    ASSERT_TRUE(trigger_->connected());
    writer_ = std::make_unique<EventWriter>(EventWriter::OpenWhenRead(fifo_, 2000ms));
    ASSERT_TRUE(writer_->ok());
  }

  // What the loop does when poll says the fd is readable.
  int Deliver(const std::vector<input_event>& events) {
    EXPECT_TRUE(writer_->Write(events));
    pollfd p{trigger_->PollFd(), POLLIN, 0};
    EXPECT_EQ(::poll(&p, 1, 1000), 1);
    return trigger_->Service(now_, p.revents);
  }

  std::filesystem::path fifo_;
  std::unique_ptr<InputTrigger> trigger_;
  std::unique_ptr<EventWriter> writer_;
  std::chrono::steady_clock::time_point now_;
};

TEST_F(InputTriggerTest, APressIsKeyDownOfTheConfiguredKey) {
  EXPECT_EQ(Deliver(Key(KEY_CAMERA, 1, 1000)), 1);
  EXPECT_EQ(Deliver(Key(KEY_CAMERA, 0, 1100)), 0);  // release
  EXPECT_EQ(trigger_->stats().presses, 1);
  EXPECT_FALSE(trigger_->Deadline().has_value());  // connected: nothing to do on a timer
}

TEST_F(InputTriggerTest, AutorepeatReleaseAndOtherKeysAreIgnored) {
  EXPECT_EQ(Deliver(Concat({Key(KEY_CAMERA, 1, 1000),
                            Key(KEY_CAMERA, 2, 1250),
                            Key(KEY_CAMERA, 2, 1283),
                            Key(KEY_CAMERA, 2, 1316),
                            Key(KEY_CAMERA, 0, 1400),
                            Key(KEY_ENTER, 1, 2000),
                            Key(KEY_ENTER, 0, 2100),
                            {Event(EV_MSC, KEY_CAMERA, 1, 2200)},  // same code, not a key event
                            {Event(EV_ABS, KEY_CAMERA, 1, 2300)}})),
            1);
  EXPECT_EQ(trigger_->stats().repeats, 3);
  EXPECT_EQ(trigger_->stats().presses, 1);
}

TEST_F(InputTriggerTest, ContactBounceWithinTheDebounceIsOnePress) {
  // Press, bounce open 4 ms later and closed again 12 ms after the press, then a real second
  // press 300 ms later, and one exactly at the debounce boundary after that.
  EXPECT_EQ(Deliver(Concat({Key(KEY_CAMERA, 1, 5000),
                            Key(KEY_CAMERA, 0, 5004),
                            Key(KEY_CAMERA, 1, 5012),
                            Key(KEY_CAMERA, 0, 5090),
                            Key(KEY_CAMERA, 1, 5300),
                            Key(KEY_CAMERA, 0, 5320),
                            Key(KEY_CAMERA, 1, 5349),  // 49 ms after the last press: bounce
                            Key(KEY_CAMERA, 0, 5349),
                            Key(KEY_CAMERA, 1, 5350)})),  // 50 ms: a press
            3);
  EXPECT_EQ(trigger_->stats().bounces, 2);
}

TEST_F(InputTriggerTest, ARecordSplitAcrossReadsIsReassembled) {
  const std::vector<input_event> press = Key(KEY_CAMERA, 1, 1000);
  const char* bytes = reinterpret_cast<const char*>(press.data());
  const size_t half = sizeof(input_event) / 2;
  ASSERT_TRUE(writer_->WriteBytes(bytes, half));
  pollfd p{trigger_->PollFd(), POLLIN, 0};
  ASSERT_EQ(::poll(&p, 1, 1000), 1);
  EXPECT_EQ(trigger_->Service(now_, p.revents), 0);
  ASSERT_TRUE(writer_->WriteBytes(bytes + half, press.size() * sizeof(input_event) - half));
  ASSERT_EQ(::poll(&p, 1, 1000), 1);
  EXPECT_EQ(trigger_->Service(now_, p.revents), 1);
}

TEST_F(InputTriggerTest, AVanishedDeviceIsReopenedAfterTheRetryInterval) {
  EXPECT_EQ(Deliver(Key(KEY_CAMERA, 1, 1000)), 1);
  writer_->Close();  // the device goes away: the reader sees end of file
  pollfd p{trigger_->PollFd(), POLLIN, 0};
  ASSERT_EQ(::poll(&p, 1, 1000), 1);
  EXPECT_EQ(trigger_->Service(now_, p.revents), 0);
  EXPECT_FALSE(trigger_->connected());
  EXPECT_EQ(trigger_->PollFd(), -1);
  EXPECT_EQ(trigger_->stats().disconnects, 1);
  ASSERT_TRUE(trigger_->Deadline().has_value());
  EXPECT_EQ(*trigger_->Deadline(), now_ + 1000ms);

  // Gone from /dev as well: the retry fails and is scheduled again.
  std::filesystem::remove(fifo_);
  EXPECT_EQ(trigger_->Service(now_ + 999ms, 0), 0);  // not due yet
  EXPECT_EQ(trigger_->Service(now_ + 1000ms, 0), 0);
  EXPECT_FALSE(trigger_->connected());
  EXPECT_EQ(*trigger_->Deadline(), now_ + 2000ms);

  // Plugged in again: the next retry opens it and presses count again.
  ASSERT_EQ(::mkfifo(fifo_.c_str(), 0600), 0);
  EXPECT_EQ(trigger_->Service(now_ + 2000ms, 0), 0);
  ASSERT_TRUE(trigger_->connected());
  EXPECT_EQ(trigger_->stats().opens, 2);
  writer_ = std::make_unique<EventWriter>(EventWriter::OpenWhenRead(fifo_, 2000ms));
  ASSERT_TRUE(writer_->ok());
  EXPECT_EQ(Deliver(Key(KEY_CAMERA, 1, 9000)), 1);
  EXPECT_EQ(trigger_->stats().presses, 2);
}

TEST(InputTriggerMissing, AMissingDeviceIsRetriedNotFatal) {
  InputTriggerOptions options;
  options.device = "/nonexistent/input/event9";
  options.retry = 500ms;
  InputTrigger trigger(options);
  const auto now = std::chrono::steady_clock::now();
  EXPECT_EQ(trigger.Service(now, 0), 0);
  EXPECT_FALSE(trigger.connected());
  EXPECT_EQ(trigger.Deadline(), now + 500ms);
  EXPECT_EQ(trigger.Describe(), "input /nonexistent/input/event9 KEY_CAMERA");
}

}  // namespace
}  // namespace px::device
