// The sd_notify protocol against a real datagram socket (path and abstract names), the
// watchdog's environment, the STATUS/STOPPING sequence and the pinger's schedule.
#include <gtest/gtest.h>
#include <unistd.h>

#include "device/systemd/notify_socket.h"
#include "device/systemd/notify_test_util.h"
#include "device/systemd/systemd_notifier.h"
#include "device/systemd/watchdog_pinger.h"
#include "tests/testing/temp_dir.h"

namespace px::device {
namespace {

using namespace std::chrono_literals;
using testing::NotifyReceiver;

std::string AbstractName() { return "@px-notify-test-" + std::to_string(::getpid()); }

TEST(NotifySocket, SendsToAnAbstractName) {
  NotifyReceiver receiver(AbstractName());
  ASSERT_TRUE(receiver.bound());
  auto socket = NotifySocket::Open(AbstractName());
  ASSERT_TRUE(socket.ok()) << socket.status().ToString();
  ASSERT_TRUE((*socket)->Send("READY=1\nSTATUS=idle").ok());
  EXPECT_EQ(receiver.Receive(1000ms), "READY=1\nSTATUS=idle");
}

TEST(NotifySocket, SendsToAPath) {
  px::testing::TempDir dir;
  const std::string path = (dir.path() / "notify").string();
  NotifyReceiver receiver(path);
  ASSERT_TRUE(receiver.bound());
  auto socket = NotifySocket::Open(path);
  ASSERT_TRUE(socket.ok()) << socket.status().ToString();
  ASSERT_TRUE((*socket)->Send("WATCHDOG=1").ok());
  EXPECT_EQ(receiver.Receive(1000ms), "WATCHDOG=1");
}

TEST(NotifySocket, RefusesAddressesItCannotUse) {
  for (const char* bad : {"", "relative/notify", "vsock:2:1234", "@"}) {
    auto socket = NotifySocket::Open(bad);
    ASSERT_FALSE(socket.ok()) << bad;
    EXPECT_EQ(socket.status().code(), StatusCode::kInvalidArgument) << bad;
  }
  EXPECT_FALSE(NotifySocket::Open("/" + std::string(200, 'x')).ok());
}

TEST(NotifySocket, NobodyListeningIsUnavailableWithTheReason) {
  auto socket = NotifySocket::Open("/nonexistent/notify.sock");
  ASSERT_TRUE(socket.ok());
  Status sent = (*socket)->Send("READY=1");
  EXPECT_EQ(sent.code(), StatusCode::kUnavailable);
  EXPECT_NE(sent.message().find("No such file or directory"), std::string::npos) << sent.ToString();
}

TEST(WatchdogEnvironment, ReadsUsecAndHonoursThePid) {
  EXPECT_FALSE(WatchdogIntervalFromEnvironment(nullptr, nullptr).value().has_value());
  EXPECT_EQ(WatchdogIntervalFromEnvironment("30000000", nullptr).value(), 30s);
  const std::string me = std::to_string(::getpid());
  EXPECT_EQ(WatchdogIntervalFromEnvironment("200000", me.c_str()).value(), 200ms);
  // WATCHDOG_PID names another process (we were forked or exec'd by the service's main process).
  const std::string other = std::to_string(::getpid() + 1);
  EXPECT_FALSE(WatchdogIntervalFromEnvironment("200000", other.c_str()).value().has_value());
  EXPECT_EQ(WatchdogIntervalFromEnvironment("0", nullptr).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(WatchdogIntervalFromEnvironment("12s", nullptr).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(WatchdogIntervalFromEnvironment("1000", "me").status().code(), StatusCode::kInvalidArgument);
}

TEST(SystemdNotifier, StatusOnChangesReadyAndOneStopping) {
  NotifyReceiver receiver(AbstractName() + "-states");
  ASSERT_TRUE(receiver.bound());
  SystemdNotifier notifier(NotifySocket::Open(AbstractName() + "-states").value(), std::nullopt);
  EXPECT_EQ(notifier.MakeWatchdogPinger(), nullptr);  // no watchdog asked for
  notifier.ReportState("idle", false);
  notifier.Ready();
  notifier.ReportState("capturing", false);
  notifier.ReportState("capturing", false);  // no change: nothing sent
  notifier.ReportState("processing", false);
  notifier.ReportState("processing", true);
  notifier.ReportState("idle", true);
  notifier.Stopping();  // already said
  for (const char* want : {"STATUS=idle",
                           "READY=1\nSTATUS=idle",
                           "STATUS=capturing",
                           "STATUS=processing",
                           "STOPPING=1\nSTATUS=stopping (processing)",
                           "STATUS=stopping (idle)"}) {
    EXPECT_EQ(receiver.Receive(1000ms), want);
  }
  EXPECT_EQ(receiver.Receive(100ms), std::nullopt);
}

TEST(WatchdogPinger, PingsEveryHalfIntervalFromWhenItRan) {
  int pings = 0;
  WatchdogPinger pinger(200ms, [&] {
    pings++;
    return OkStatus();
  });
  const auto start = *pinger.Deadline();
  EXPECT_EQ(pinger.PollFd(), -1);
  pinger.Service(start, 0);
  EXPECT_EQ(pings, 1);
  EXPECT_EQ(*pinger.Deadline(), start + 100ms);
  pinger.Service(start + 50ms, 0);  // early: nothing
  EXPECT_EQ(pings, 1);
  // A loop that stalled for a second pings once, not ten times.
  pinger.Service(start + 1100ms, 0);
  EXPECT_EQ(pings, 2);
  EXPECT_EQ(*pinger.Deadline(), start + 1200ms);
}

}  // namespace
}  // namespace px::device
