// The libcamera FrameSource ("libcamera"): one still-capture stream of a camera libcamera lists,
// one request per Next(). Written against libcamera 0.0.3 (Debian 12). See README.md.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "drivers/source/frame_source.h"

namespace px::libcamera_driver {

struct LibcameraOptions {
  std::string camera_id;                  // libcamera's id; "" = the first camera listed
  std::filesystem::path rig_calibration;  // RigCalibration JSON for Describe(); "" = none known
};

// Loads the rig calibration (errors name the file) and returns the source. The camera itself is
// looked up and acquired at Configure, so a camera plugged in later is found then; until then
// Configure fails with UNAVAILABLE naming the camera.
StatusOr<std::unique_ptr<FrameSource>> OpenLibcameraSource(const LibcameraOptions& options);

// What libcamera sees now (starts the camera manager, or shares the running one).
struct LibcameraInventory {
  std::string version;                  // libcamera's version string, "0.0.3"
  std::vector<std::string> camera_ids;  // in libcamera's order
};
StatusOr<LibcameraInventory> ListLibcameraCameras();

}  // namespace px::libcamera_driver
