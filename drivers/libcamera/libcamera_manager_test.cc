// Starts the real libcamera CameraManager. This machine has no camera (PLATFORM.md), so the
// list is expected to be empty here; the test still checks that the manager starts, reports its
// version, can be shared and restarted, and that a source for a missing camera says so.
#include <gtest/gtest.h>

#include "drivers/libcamera/libcamera_source.h"

namespace px::libcamera_driver {
namespace {

TEST(LibcameraManager, StartsAndListsCameras) {
  auto inventory = ListLibcameraCameras();
  ASSERT_TRUE(inventory.ok()) << inventory.status().ToString();
  EXPECT_FALSE(inventory->version.empty());
  std::string ids;
  for (const std::string& id : inventory->camera_ids) ids += " '" + id + "'";
  std::cout << "libcamera " << inventory->version << " lists " << inventory->camera_ids.size() << " camera(s):" << ids
            << "\n";
  // The manager stops with the last user and starts again (libcamera allows one per process).
  auto again = ListLibcameraCameras();
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  EXPECT_EQ(again->camera_ids, inventory->camera_ids);
}

TEST(LibcameraManager, AMissingCameraIsUnavailableByName) {
  LibcameraOptions options;
  options.camera_id = "/base/no/such/camera";
  auto source = OpenLibcameraSource(options);
  ASSERT_TRUE(source.ok()) << source.status().ToString();
  EXPECT_EQ((*source)->Name(), "libcamera");
  EXPECT_EQ((*source)->Describe().model, "libcamera:/base/no/such/camera");
  SourceConfig granted;
  auto configured = (*source)->Configure(SourceConfig{}, &granted);
  ASSERT_FALSE(configured.ok());
  EXPECT_EQ(configured.status().code(), StatusCode::kUnavailable);
  EXPECT_NE(configured.status().message().find("/base/no/such/camera"), std::string::npos)
      << configured.status().ToString();
  auto frames = (*source)->Next(std::chrono::milliseconds(100));
  EXPECT_EQ(frames.status().code(), StatusCode::kFailedPrecondition);
  (*source)->Stop();
  (*source)->Stop();
}

TEST(LibcameraManager, ABadRigCalibrationFileIsNamed) {
  LibcameraOptions options;
  options.rig_calibration = "/nonexistent/rig.json";
  auto source = OpenLibcameraSource(options);
  ASSERT_FALSE(source.ok());
  EXPECT_NE(source.status().message().find("/nonexistent/rig.json"), std::string::npos) << source.status().ToString();
}

}  // namespace
}  // namespace px::libcamera_driver
