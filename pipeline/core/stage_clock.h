// The clock the pipeline times its stages and their steps with (PipelineReport::timings, stage reports).
#pragma once

#include <chrono>

namespace px {

using Clock = std::chrono::steady_clock;

inline double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace px
