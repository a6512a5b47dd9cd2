// Simulated photos with EXIF: inserts an APP1 segment giving the focal length (and the focal
// plane resolution that converts it to pixels) into a JPEG that has none, as a camera writes it.
#pragma once

#include <cstdint>
#include <vector>

namespace px::sim {

// `jpeg` with an EXIF block whose focal length is `focal_px` pixels for a `width` x `height`
// image (FocalLength in mm at 100 px per mm, FocalPlaneXResolution, PixelX/YDimension).
std::vector<uint8_t> WithExifFocalLength(const std::vector<uint8_t>& jpeg, double focal_px, int width, int height);

}  // namespace px::sim
