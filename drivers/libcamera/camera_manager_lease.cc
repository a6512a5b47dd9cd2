#include "drivers/libcamera/camera_manager_lease.h"

#include <cstring>
#include <mutex>
#include <string>

namespace px::libcamera_driver {
namespace {

std::mutex g_mutex;
libcamera::CameraManager* g_manager = nullptr;  // guarded by g_mutex
int g_leases = 0;                               // guarded by g_mutex

void ReturnLease(libcamera::CameraManager*) {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (--g_leases > 0) return;
  g_manager->stop();
  delete g_manager;
  g_manager = nullptr;
}

}  // namespace

StatusOr<std::shared_ptr<libcamera::CameraManager>> LeaseCameraManager() {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (g_manager == nullptr) {
    auto manager = std::make_unique<libcamera::CameraManager>();
    const int ret = manager->start();
    if (ret != 0) {
      return UnavailableError("libcamera " + libcamera::CameraManager::version() +
                              ": camera manager did not start: " + std::strerror(-ret));
    }
    g_manager = manager.release();
  }
  ++g_leases;
  return std::shared_ptr<libcamera::CameraManager>(g_manager, ReturnLease);
}

}  // namespace px::libcamera_driver
