// A short soak through the real parallaxd executable: 50 presses (tiny tiles, 2-frame clips,
// four queued at a time, a quota small enough to evict): every press handled, no capture lost,
// a clip for each, the quota kept the storage bounded, and the daemon quit cleanly. RSS is
// printed, not asserted (a figure, measured by the full soak: README "Soak").
#include "device/soak/soak.h"

#include <gtest/gtest.h>

#include "tests/testing/temp_dir.h"

namespace px::device {
namespace {

TEST(SoakTest, FiftyPressesNothingLost) {
  px::testing::TempDir dir;
  SoakOptions options;
  options.parallaxd = std::filesystem::path(PX_BINARY_DIR) / "parallaxd";
  options.work_dir = dir.path() / "soak";
  options.presses = 50;
  options.tile_width = 64;
  options.tile_height = 48;
  options.clip_frames = 2;
  options.quota_mb = 2;
  options.progress_every = 10;
  auto report = RunSoak(options);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  std::cout << report->ToText();
  EXPECT_EQ(report->handled, 50);
  EXPECT_EQ(report->clips, 50);
  EXPECT_EQ(report->lost, 0);
  EXPECT_TRUE(report->failures.empty());
  EXPECT_GT(report->evicted, 0) << "the quota should have evicted old clips";
  EXPECT_LT(report->store_bytes, 3'000'000u) << "the 2 MB quota (plus journal records) bounds the storage";
  EXPECT_EQ(report->daemon_exit_code, 0);
}

TEST(SoakTest, BadOptionsNameTheField) {
  SoakOptions options;
  options.parallaxd = "parallaxd";
  options.work_dir = "/tmp/x";
  options.presses = 0;
  EXPECT_EQ(options.Validate().message(), "soak presses: 0 is not in [1, 1000000]");
  options.presses = 1;
  options.quota_mb = 0;
  EXPECT_EQ(options.Validate().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace px::device
