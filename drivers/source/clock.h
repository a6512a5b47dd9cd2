// An injectable clock, so simulated and replayed captures are deterministic in tests.
#pragma once

#include <atomic>
#include <cstdint>

namespace px {

class Clock {
 public:
  virtual ~Clock() = default;
  virtual int64_t NowNs() = 0;
};

// CLOCK_MONOTONIC.
class SteadyClock final : public Clock {
 public:
  int64_t NowNs() override;
};

// Starts at `start_ns`, advances only when told (or by `tick_ns` on every read).
class ManualClock final : public Clock {
 public:
  explicit ManualClock(int64_t start_ns = 0, int64_t tick_ns = 0) : now_ns_(start_ns), tick_ns_(tick_ns) {}
  int64_t NowNs() override { return now_ns_.fetch_add(tick_ns_); }
  void Advance(int64_t ns) { now_ns_ += ns; }

 private:
  std::atomic<int64_t> now_ns_;
  int64_t tick_ns_;
};

}  // namespace px
