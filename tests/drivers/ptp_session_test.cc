// The PTP session against the simulated camera: transactions, multi-transfer data phases,
// zero-length packets, DeviceBusy retries, event deadlines, non-OK responses, a lost device.
#include "drivers/ptp/ptp_session.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/drivers/ptp_responder.h"

namespace px::ptp::testing {
namespace {

using std::chrono::milliseconds;
using std::chrono::steady_clock;
using ::testing::HasSubstr;

std::vector<uint8_t> Pattern(size_t n) {
  std::vector<uint8_t> bytes(n);
  for (size_t i = 0; i < n; ++i) bytes[i] = static_cast<uint8_t>(i * 31 + 7);
  return bytes;
}

struct Fixture {
  explicit Fixture(ResponderOptions options, SessionOptions session_options = {}) {
    responder = std::make_shared<PtpResponder>(std::move(options));
    session_options.busy_backoff = milliseconds(2);
    session = std::make_unique<PtpSession>(MakeResponderTransport(responder), session_options);
  }
  std::shared_ptr<PtpResponder> responder;
  std::unique_ptr<PtpSession> session;
};

ResponderOptions WithObject(size_t bytes) {
  ResponderOptions options;
  options.jpegs = {Pattern(bytes)};
  return options;
}

TEST(PtpSession, DeviceInfoThenSessionWithTransactionIds) {
  Fixture f(WithObject(100));
  auto info = f.session->GetDeviceInfo();
  ASSERT_TRUE(info.ok()) << info.status().ToString();
  EXPECT_EQ(info->manufacturer, "Parallax Sim");
  EXPECT_TRUE(info->SupportsOperation(op::kInitiateCapture));
  ASSERT_TRUE(f.session->OpenSession().ok());
  ASSERT_TRUE(f.session->InitiateCapture().ok());
  ASSERT_TRUE(f.session->CloseSession().ok());
  const auto stats = f.responder->stats();
  EXPECT_EQ(stats.operations,
            (std::vector<uint16_t>{op::kGetDeviceInfo, op::kOpenSession, op::kInitiateCapture, op::kCloseSession}));
  // OpenSession is transaction 0; numbering restarts at 1 within the session.
  EXPECT_EQ(stats.transaction_ids, (std::vector<uint32_t>{0, 0, 1, 2}));
  EXPECT_EQ(stats.sessions_closed, 1);
}

TEST(PtpSession, OperationsOutsideASessionAreRefusedByTheCamera) {
  Fixture f(WithObject(100));
  auto capture = f.session->InitiateCapture();
  ASSERT_FALSE(capture.ok());
  EXPECT_EQ(capture.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(capture.status().message(), HasSubstr("InitiateCapture (0x100E)"));
  EXPECT_THAT(capture.status().message(), HasSubstr("SessionNotOpen (0x2003)"));
  EXPECT_THAT(capture.status().message(), HasSubstr("sim-ptp (1d6b:0104)"));
}

TEST(PtpSession, ALargeObjectComesInSeveralBulkTransfers) {
  const std::vector<uint8_t> object = Pattern(300'000);
  SessionOptions options;
  options.bulk_chunk_bytes = 64 * 1024;
  Fixture f(WithObject(object.size()), options);
  ASSERT_TRUE(f.session->OpenSession().ok());
  ASSERT_TRUE(f.session->InitiateCapture().ok());
  auto added = f.session->WaitForEvent(ev::kObjectAdded, steady_clock::now() + milliseconds(2000));
  ASSERT_TRUE(added.ok()) << added.status().ToString();
  ASSERT_EQ(added->params.size(), 1u);
  auto info = f.session->GetObjectInfo(added->params[0]);
  ASSERT_TRUE(info.ok()) << info.status().ToString();
  EXPECT_EQ(info->object_compressed_size, object.size());
  EXPECT_EQ(info->filename, "IMG_0001.JPG");
  auto bytes = f.session->GetObject(added->params[0]);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  EXPECT_EQ(*bytes, object);
  EXPECT_EQ(f.session->last_data_transfers(), 5);  // ceil(300012 / 65536)
  ASSERT_TRUE(f.session->DeleteObject(added->params[0]).ok());
  auto again = f.session->GetObjectInfo(added->params[0]);
  ASSERT_FALSE(again.ok());
  EXPECT_EQ(again.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(again.status().message(), HasSubstr("InvalidObjectHandle (0x2009)"));
}

TEST(PtpSession, ADataPhaseOfWholePacketsEndsWithAZeroLengthPacket) {
  const size_t payload = 3 * 512 - 12;  // container = exactly three packets
  SessionOptions options;
  options.bulk_chunk_bytes = 512;  // one packet per transfer: the ZLP comes as its own transfer
  Fixture f(WithObject(payload), options);
  ASSERT_TRUE(f.session->OpenSession().ok());
  ASSERT_TRUE(f.session->InitiateCapture().ok());
  auto added = f.session->WaitForEvent(ev::kObjectAdded, steady_clock::now() + milliseconds(2000));
  ASSERT_TRUE(added.ok());
  auto bytes = f.session->GetObject(added->params[0]);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  EXPECT_EQ(bytes->size(), payload);
  // The next transaction still lines up after the zero-length packet.
  ASSERT_TRUE(f.session->DeleteObject(added->params[0]).ok());
  EXPECT_GE(f.responder->stats().zero_length_packets, 1);
}

TEST(PtpSession, DeviceBusyIsRetried) {
  ResponderOptions options = WithObject(10);
  options.busy_replies = 3;
  Fixture f(options);
  ASSERT_TRUE(f.session->OpenSession().ok());
  auto capture = f.session->InitiateCapture();
  ASSERT_TRUE(capture.ok()) << capture.status().ToString();
  EXPECT_EQ(f.responder->stats().busy_answers, 3);
  EXPECT_EQ(f.responder->stats().captures, 1);
}

TEST(PtpSession, DeviceBusyForeverIsUnavailableNamingOperationAndCode) {
  ResponderOptions options = WithObject(10);
  options.busy_replies = 100;
  SessionOptions session;
  session.busy_retries = 2;
  Fixture f(options, session);
  ASSERT_TRUE(f.session->OpenSession().ok());
  auto capture = f.session->InitiateCapture();
  ASSERT_FALSE(capture.ok());
  EXPECT_EQ(capture.status().code(), StatusCode::kUnavailable);
  EXPECT_THAT(capture.status().message(), HasSubstr("InitiateCapture (0x100E)"));
  EXPECT_THAT(capture.status().message(), HasSubstr("DeviceBusy (0x2019) 3 times"));
  EXPECT_EQ(f.responder->stats().busy_answers, 3);
  EXPECT_FALSE(f.session->device_gone());
}

TEST(PtpSession, ANonOkResponseNamesTheOperationAndCode) {
  ResponderOptions options = WithObject(10);
  options.fail_operation = op::kGetObject;
  options.fail_response = rc::kAccessDenied;
  Fixture f(options);
  ASSERT_TRUE(f.session->OpenSession().ok());
  ASSERT_TRUE(f.session->InitiateCapture().ok());
  auto added = f.session->WaitForEvent(ev::kObjectAdded, steady_clock::now() + milliseconds(2000));
  ASSERT_TRUE(added.ok());
  auto bytes = f.session->GetObject(added->params[0]);
  ASSERT_FALSE(bytes.ok());
  EXPECT_EQ(bytes.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(bytes.status().message(), HasSubstr("GetObject (0x1009)"));
  EXPECT_THAT(bytes.status().message(), HasSubstr("AccessDenied (0x200F)"));
  // The session goes on: the failed transaction consumed its response.
  EXPECT_TRUE(f.session->GetObjectInfo(added->params[0]).ok());
}

TEST(PtpSession, AnEventThatNeverComesHitsTheDeadline) {
  ResponderOptions options = WithObject(10);
  options.never_send_event = true;
  Fixture f(options);
  ASSERT_TRUE(f.session->OpenSession().ok());
  ASSERT_TRUE(f.session->InitiateCapture().ok());
  const auto start = steady_clock::now();
  auto added = f.session->WaitForEvent(ev::kObjectAdded, start + milliseconds(250));
  const auto waited = std::chrono::duration_cast<milliseconds>(steady_clock::now() - start);
  ASSERT_FALSE(added.ok());
  EXPECT_EQ(added.status().code(), StatusCode::kDeadlineExceeded);
  EXPECT_THAT(added.status().message(), HasSubstr("ObjectAdded (0x4002)"));
  EXPECT_THAT(added.status().message(), HasSubstr("sim-ptp (1d6b:0104)"));
  EXPECT_GE(waited.count(), 240);
  EXPECT_LT(waited.count(), 2000);
}

TEST(PtpSession, OtherEventsAreSkippedWhileWaiting) {
  Fixture f(WithObject(10));
  ASSERT_TRUE(f.session->OpenSession().ok());
  ASSERT_TRUE(f.session->InitiateCapture().ok());
  // The responder queues ObjectAdded then CaptureComplete: waiting for the second skips the first.
  auto complete = f.session->WaitForEvent(ev::kCaptureComplete, steady_clock::now() + milliseconds(2000));
  ASSERT_TRUE(complete.ok()) << complete.status().ToString();
  EXPECT_EQ(complete->params, (std::vector<uint32_t>{1}));  // InitiateCapture was transaction 1
}

TEST(PtpSession, AnUnpluggedCameraIsUnavailableAndStaysSo) {
  Fixture f(WithObject(10));
  ASSERT_TRUE(f.session->OpenSession().ok());
  f.responder->Unplug();
  auto capture = f.session->InitiateCapture();
  ASSERT_FALSE(capture.ok());
  EXPECT_EQ(capture.status().code(), StatusCode::kUnavailable);
  EXPECT_THAT(capture.status().message(), HasSubstr("LIBUSB_ERROR_NO_DEVICE"));
  EXPECT_TRUE(f.session->device_gone());
  auto again = f.session->GetDeviceInfo();
  EXPECT_EQ(again.status().code(), StatusCode::kUnavailable);
}

}  // namespace
}  // namespace px::ptp::testing
