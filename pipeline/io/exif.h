// The few EXIF tags hand-held structure from motion needs (focal length, its 35 mm equivalent,
// the focal plane resolution, orientation), read from a JPEG's APP1 segment. No dependency:
// the TIFF structure is small, and only IFD0 and the Exif sub-IFD are visited.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace px {

struct ExifInfo {
  std::string make;
  std::string model;
  int orientation = 1;                  // 1 = upright (TIFF orientation tag); 0 when absent
  double focal_length_mm = 0;           // 0 when absent
  double focal_length_35mm = 0;         // 35 mm film equivalent, 0 when absent
  double focal_plane_x_resolution = 0;  // pixels per focal-plane unit, 0 when absent
  double focal_plane_unit_mm = 0;       // the unit: 25.4 (inch) or 10 (cm)
  int pixel_width = 0;                  // the Exif image size the resolution refers to (0 when absent)
  int pixel_height = 0;

  // Focal length in pixels for an upright image of width x height: from the focal plane
  // resolution when given (scaled from the Exif pixel size), else from the 35 mm equivalent
  // (over the diagonal: 43.27 mm for 35 mm film); 0 when neither is known.
  double FocalPx(int width, int height, std::string* source = nullptr) const;
};

// Parses a JPEG file's bytes. A JPEG without EXIF gives an ExifInfo with nothing set (not an
// error); a file that is not a JPEG, or a truncated EXIF block, is an error naming the offset.
StatusOr<ExifInfo> ParseJpegExif(const std::vector<uint8_t>& bytes);
StatusOr<ExifInfo> ReadJpegExif(const std::filesystem::path& file);

}  // namespace px
