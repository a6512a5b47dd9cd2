// The real parallaxd process under a stand-in for systemd: NOTIFY_SOCKET names an abstract
// datagram socket this test binds, WATCHDOG_USEC asks for pings. Checks READY=1, STATUS on every
// state change of a real press (simulated camera, real pipeline, small sizes), periodic
// WATCHDOG=1 at about half the interval, and STOPPING=1 on SIGTERM with a clean exit.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <vector>

#include "device/control/control_client.h"
#include "device/systemd/notify_test_util.h"
#include "pipeline/io/durable_file.h"
#include "tests/testing/temp_dir.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

std::string ReadLog(const fs::path& path) {
  auto text = ReadFileToString(path);
  return text.ok() ? *text : "(no log)";
}

// Waits up to `timeout` for the child; its exit status, or -1 (then it is killed).
int WaitExit(pid_t pid, std::chrono::milliseconds timeout) {
  const auto end = Clock::now() + timeout;
  while (Clock::now() < end) {
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid)
      return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    std::this_thread::sleep_for(20ms);
  }
  ::kill(pid, SIGKILL);
  ::waitpid(pid, nullptr, 0);
  return -1;
}

TEST(ParallaxdNotify, ReadyStatusWatchdogAndStopping) {
  px::testing::TempDir dir;
  const std::string notify = "@px-parallaxd-notify-" + std::to_string(::getpid());
  testing::NotifyReceiver receiver(notify);
  ASSERT_TRUE(receiver.bound());
  const fs::path config = dir.path() / "parallaxd.json";
  ASSERT_TRUE(WriteFileAtomically(config,
                                  R"({
    "storage": {"root": ")" + (dir.path() / "store").string() +
                                      R"(", "min_free_mb": 0},
    "control": {"socket": ")" + (dir.path() / "ctl.sock").string() +
                                      R"("},
    "source": {"sim": {"tile_width": 160}},
    "clip": {"duration_s": 0.5, "fps": 10}
  })")
                  .ok());
  const fs::path log = dir.path() / "parallaxd.log";

  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::setenv("NOTIFY_SOCKET", notify.c_str(), 1);
    ::setenv("WATCHDOG_USEC", "300000", 1);  // pings every 150 ms
    ::unsetenv("WATCHDOG_PID");
    ::unsetenv("PARALLAX_CONFIG");
    FILE* err = std::freopen(log.c_str(), "w", stderr);
    (void)err;
    const std::string binary = std::string(PX_BINARY_DIR) + "/parallaxd";
    ::execl(binary.c_str(), binary.c_str(), "--config", config.c_str(), static_cast<char*>(nullptr));
    std::_Exit(127);
  }

  // Everything up to READY=1 (STATUS=idle may come first).
  std::vector<std::string> messages;
  const auto ready_by = Clock::now() + 30s;
  bool ready = false;
  while (!ready && Clock::now() < ready_by) {
    if (auto message = receiver.Receive(500ms)) {
      messages.push_back(*message);
      ready = message->find("READY=1") != std::string::npos;
    }
  }
  ASSERT_TRUE(ready) << ReadLog(log);
  EXPECT_NE(messages.back().find("STATUS=idle"), std::string::npos) << messages.back();
  // The socket listens when READY=1 arrives.
  EXPECT_TRUE(ControlClient::Connect(dir.path() / "ctl.sock").ok());

  // Pings, about every 150 ms.
  std::vector<Clock::time_point> pings;
  const auto watch_until = Clock::now() + 1200ms;
  while (Clock::now() < watch_until) {
    auto message = receiver.Receive(300ms);
    if (message == "WATCHDOG=1") pings.push_back(Clock::now());
  }
  ASSERT_GE(pings.size(), 5u) << ReadLog(log);
  std::vector<double> gaps_ms;
  for (size_t i = 1; i < pings.size(); ++i) {
    gaps_ms.push_back(std::chrono::duration<double, std::milli>(pings[i] - pings[i - 1]).count());
  }
  std::sort(gaps_ms.begin(), gaps_ms.end());
  const double median_ms = gaps_ms[gaps_ms.size() / 2];
  std::cout << "watchdog pings: " << pings.size() << " in 1.2 s, median gap " << median_ms << " ms\n";
  EXPECT_GT(median_ms, 100);
  EXPECT_LT(median_ms, 250);

  // A press: STATUS follows the daemon's states back to idle, with pings all along.
  auto client = ControlClient::Connect(dir.path() / "ctl.sock");
  ASSERT_TRUE(client.ok()) << client.status().ToString();
  auto reply = (*client)->Call(R"({"cmd":"capture"})");
  ASSERT_TRUE(reply.ok()) << reply.status().ToString();
  std::vector<std::string> statuses;
  int pings_during_job = 0;
  const auto job_by = Clock::now() + 90s;
  while (Clock::now() < job_by && (statuses.empty() || statuses.back() != "STATUS=idle")) {
    auto message = receiver.Receive(1000ms);
    if (!message) continue;
    if (*message == "WATCHDOG=1") {
      pings_during_job++;
    } else {
      statuses.push_back(*message);
    }
  }
  ASSERT_EQ(statuses, (std::vector<std::string>{"STATUS=capturing", "STATUS=processing", "STATUS=idle"}))
      << ReadLog(log);
  EXPECT_GE(pings_during_job, 1);

  ASSERT_EQ(::kill(pid, SIGTERM), 0);
  bool stopping = false;
  const auto stop_by = Clock::now() + 20s;
  while (!stopping && Clock::now() < stop_by) {
    auto message = receiver.Receive(500ms);
    stopping = message && message->rfind("STOPPING=1", 0) == 0;
  }
  EXPECT_TRUE(stopping) << ReadLog(log);
  EXPECT_EQ(WaitExit(pid, 20s), 0) << ReadLog(log);
}

}  // namespace
}  // namespace px::device
