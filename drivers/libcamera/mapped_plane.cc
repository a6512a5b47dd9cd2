#include "drivers/libcamera/mapped_plane.h"

#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <utility>

namespace px::libcamera_driver {

StatusOr<MappedPlane> MappedPlane::Map(int fd, size_t offset, size_t length) {
  const std::string what = "plane of fd " + std::to_string(fd) + " at offset " + std::to_string(offset) + ", " +
                           std::to_string(length) + " bytes";
  if (fd < 0) return InvalidArgumentError(what + ": invalid fd");
  if (length == 0) return InvalidArgumentError(what + ": empty plane");
  // mmap wants a page-aligned offset: map from the page holding `offset`.
  const size_t page = static_cast<size_t>(::sysconf(_SC_PAGESIZE));
  const size_t aligned = offset - offset % page;
  const size_t lead = offset - aligned;
  void* base = ::mmap(nullptr, lead + length, PROT_READ, MAP_SHARED, fd, static_cast<off_t>(aligned));
  if (base == MAP_FAILED) return UnavailableError(what + ": mmap failed: " + std::strerror(errno));
  MappedPlane plane;
  plane.base_ = base;
  plane.base_length_ = lead + length;
  plane.data_ = static_cast<const uint8_t*>(base) + lead;
  plane.length_ = length;
  return plane;
}

MappedPlane::MappedPlane(MappedPlane&& other) noexcept { *this = std::move(other); }

MappedPlane& MappedPlane::operator=(MappedPlane&& other) noexcept {
  if (this != &other) {
    Reset();
    std::swap(base_, other.base_);
    std::swap(base_length_, other.base_length_);
    std::swap(data_, other.data_);
    std::swap(length_, other.length_);
  }
  return *this;
}

MappedPlane::~MappedPlane() { Reset(); }

void MappedPlane::Reset() {
  if (base_ != nullptr) ::munmap(base_, base_length_);
  base_ = nullptr;
  base_length_ = 0;
  data_ = nullptr;
  length_ = 0;
}

}  // namespace px::libcamera_driver
