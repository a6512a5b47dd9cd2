// CIPA DC-007 Multi-Picture Object files (.mpo: Fuji FinePix Real 3D, Nintendo 3DS, Panasonic's 3D
// lens): several JPEGs in one file, listed by the MP index (the APP2 "MPF" segment of the first
// image, a TIFF structure whose MP entry tag gives each image's size and offset). Only the index is
// read here; each image is an ordinary JPEG with its own EXIF.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace px {

// The JPEG bytes of every image in the file, in the MP index's order. `name` labels the errors
// (DATA_LOSS): not a JPEG, no MP index, an index that is truncated or garbled, an image that
// lies outside the file or is not a JPEG.
StatusOr<std::vector<std::vector<uint8_t>>> SplitMpo(const std::vector<uint8_t>& bytes, const std::string& name);

}  // namespace px
