// A read-only memory mapping of one buffer plane: libcamera hands out dmabuf fds, and each plane
// lives in its fd at an offset that need not be page aligned. Works on any mappable fd (memfd in
// tests). Move-only; unmaps on destruction.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pipeline/core/status.h"

namespace px::libcamera_driver {

class MappedPlane {
 public:
  // Maps `length` bytes of `fd` starting at `offset`. Errors name the fd, range and errno text.
  static StatusOr<MappedPlane> Map(int fd, size_t offset, size_t length);

  MappedPlane() = default;
  MappedPlane(MappedPlane&& other) noexcept;
  MappedPlane& operator=(MappedPlane&& other) noexcept;
  MappedPlane(const MappedPlane&) = delete;
  MappedPlane& operator=(const MappedPlane&) = delete;
  ~MappedPlane();

  const uint8_t* data() const { return data_; }  // the byte at `offset`
  size_t length() const { return length_; }

 private:
  void Reset();
  void* base_ = nullptr;  // page-aligned start of the mapping
  size_t base_length_ = 0;
  const uint8_t* data_ = nullptr;
  size_t length_ = 0;
};

}  // namespace px::libcamera_driver
