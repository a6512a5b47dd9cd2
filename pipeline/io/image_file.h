// Decoding a photo that came from outside (a user's folder, a camera's card, an MPO's image) without
// trusting it: the size its header claims is checked against a limit before any pixel is decoded
// (a crafted PNG claiming 40000x40000 pixels costs nothing), a JPEG is decoded already reduced by
// libjpeg's DCT scaling when only a smaller image is wanted, and every decoder failure becomes an
// error naming the file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <span>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace px {

struct ImageDecodeOptions {
  // Images whose header claims more pixels than this are refused before decoding. The default is
  // well above any camera's photo (a 100 MP medium-format frame) and bounds a decode's memory to
  // about 1 GB of BGR.
  double max_pixels = 300e6;
  // When > 0: a JPEG is decoded at 1/2, 1/4 or 1/8 of its size, the smallest whose longer side still
  // reaches this (other formats decode at full size). 0 = full size.
  int min_longer_side_px = 0;
  // Honour the EXIF orientation (JPEG): the photo upright, as a viewer shows it. False: the
  // sensor's pixels as they lie.
  bool apply_orientation = true;
};

// The width and height an image's header claims (JPEG: its frame header; PNG: IHDR; GIF: the
// logical screen; WebP: VP8, VP8L or VP8X), before any decoding. Errors: truncated or not an image
// of those formats.
struct ImageHeaderSize {
  int64_t width = 0;
  int64_t height = 0;
};
StatusOr<ImageHeaderSize> ReadImageHeaderSize(std::span<const uint8_t> bytes);

// The image as 8-bit BGR. `name` (the file, or "FILE image 2") heads every error.
StatusOr<cv::Mat> DecodeImageBytes(std::span<const uint8_t> bytes,
                                   const std::string& name,
                                   const ImageDecodeOptions& options = {});
StatusOr<cv::Mat> DecodeImageFile(const std::filesystem::path& file, const ImageDecodeOptions& options = {});

// The file's bytes, refused unread when it is larger than any image within the limit could be.
StatusOr<std::vector<uint8_t>> ReadImageFileBytes(const std::filesystem::path& file,
                                                  const ImageDecodeOptions& options = {});

}  // namespace px
