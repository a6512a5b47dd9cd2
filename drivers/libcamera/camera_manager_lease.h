// libcamera allows one CameraManager per process (a second one is a fatal error), so every user
// in the process shares one, started on first use and stopped when the last lease goes.
#pragma once

#include <libcamera/camera_manager.h>

#include <memory>

#include "pipeline/core/status.h"

namespace px::libcamera_driver {

// A started CameraManager; UNAVAILABLE (with libcamera's version and errno text) when it fails.
StatusOr<std::shared_ptr<libcamera::CameraManager>> LeaseCameraManager();

}  // namespace px::libcamera_driver
