#include "device/test_pause.h"

#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>

#include "pipeline/core/log.h"

namespace px::device {

void PauseHereIfAsked(std::string_view phase) {
  static const std::string wanted = [] {
    const char* value = std::getenv(kTestPauseEnv);
    return std::string(value == nullptr ? "" : value);
  }();
  if (wanted.empty() || wanted != phase) return;
  auto log = Logger("device");
  log->warn("paused at {} ({} is set; waiting to be killed)", phase, kTestPauseEnv);
  log->flush();
  while (true) std::this_thread::sleep_for(std::chrono::hours(1));
}

}  // namespace px::device
