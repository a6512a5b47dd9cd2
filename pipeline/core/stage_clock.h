// The clock the pipeline times its stages and their steps with (PipelineReport::timings, stage reports).
#pragma once

#include <chrono>

namespace px {

using StageClock = std::chrono::steady_clock;

inline double MsSince(StageClock::time_point start) {
  return std::chrono::duration<double, std::milli>(StageClock::now() - start).count();
}

}  // namespace px
