// The frame-source conformance suite: every FrameSource (simulated, replayed, real drivers
// against emulated devices) must honour the contract of drivers/source/frame_source.h in the same
// way. The tests live in frame_source_conformance.cc; each source family instantiates them in its
// own test binary (it may need its own environment, e.g. umockdev's preload library):
//
//   INSTANTIATE_TEST_SUITE_P(V4l2, FrameSourceConformance, ::testing::Values(SourceCase{...}),
//                            SourceCaseName);
//
// A source whose hardware (or stand-in) is absent makes its case GTEST_SKIP() with a reason, by
// returning a Status with code UNAVAILABLE from `make`.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "drivers/source/clock.h"
#include "drivers/source/frame_source.h"
#include "tests/testing/temp_dir.h"

namespace px::conformance {

struct SourceCase {
  std::string name;
  // Builds the source; `dir` is a per-test temporary folder it may use.
  std::function<StatusOr<std::unique_ptr<FrameSource>>(const std::filesystem::path& dir, Clock* clock)> make;
};

// Test names from SourceCase::name (letters, digits and underscores only).
std::string SourceCaseName(const ::testing::TestParamInfo<SourceCase>& info);

class FrameSourceConformance : public ::testing::TestWithParam<SourceCase> {
 protected:
  void SetUp() override;

  // Configures the source's native size in RGB888 (sources convert or adjust the format).
  ConfigureResult ConfigureNative(SourceConfig* granted);

  px::testing::TempDir dir_;
  ManualClock clock_{1'000'000'000, 1'000'000};
  std::unique_ptr<FrameSource> source_;
};

}  // namespace px::conformance
