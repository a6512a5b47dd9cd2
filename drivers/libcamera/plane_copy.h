// Copies a camera buffer's planes, whose rows may be padded (stride > row bytes), into a tightly
// packed px::RawImage. Independent of libcamera so it is unit-testable with any memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "pipeline/core/pixel_format.h"

namespace px::libcamera_driver {

// One plane as the camera filled it.
struct PlaneView {
  const uint8_t* data = nullptr;
  size_t bytes = 0;   // readable bytes from `data` (what the camera reports as used)
  size_t stride = 0;  // bytes from one row's start to the next; 0 = tightly packed
};

// The packed layout of `format`: bytes per row and rows for each plane.
struct PackedPlane {
  size_t row_bytes = 0;
  int rows = 0;
};
StatusOr<std::vector<PackedPlane>> PackedPlanes(PixelFormat format, int width, int height);

// Packs `planes` into a RawImage of `format` and size. NV12 may come as two planes or as one
// plane holding Y then UV at the same stride. Errors: INVALID_ARGUMENT for a stride below the
// row size or a wrong plane count, DATA_LOSS for a plane too short for its rows (naming the
// plane, its bytes and what the rows need).
StatusOr<RawImage> CopyPlanes(PixelFormat format, int width, int height, const std::vector<PlaneView>& planes);

}  // namespace px::libcamera_driver
