// The conformance suite over the libcamera driver with the first camera libcamera lists. On a
// machine without a camera (this build machine: libcamera 0.0.3 starts and lists none, and a
// fake media device under umockdev is not picked up, see ../shared/PLATFORM.md) every case skips
// with that reason; with a camera attached it runs for real.
#include "drivers/libcamera/libcamera_source.h"
#include "tests/conformance/frame_source_conformance.h"

namespace px::conformance {
namespace {

StatusOr<std::unique_ptr<FrameSource>> MakeLibcamera() {
  PX_ASSIGN_OR_RETURN(libcamera_driver::LibcameraInventory inventory, libcamera_driver::ListLibcameraCameras());
  if (inventory.camera_ids.empty()) {
    return UnavailableError("libcamera " + inventory.version +
                            " lists no cameras on this machine (no camera attached; libcamera has no virtual "
                            "camera in this version); the suite runs when one is");
  }
  libcamera_driver::LibcameraOptions options;
  options.camera_id = inventory.camera_ids.front();
  return libcamera_driver::OpenLibcameraSource(options);
}

INSTANTIATE_TEST_SUITE_P(Libcamera,
                         FrameSourceConformance,
                         ::testing::Values(SourceCase{"libcamera_first_camera",
                                                      [](const auto&, Clock*) { return MakeLibcamera(); }}),
                         SourceCaseName);

}  // namespace
}  // namespace px::conformance
