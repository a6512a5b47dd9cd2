// How one frame's bytes are stored in a recording: lossless PNG for complete RGB888, BGR888 and
// GRAY8 images (decoding gives back the exact bytes), the camera's own JPEG file as it came for an
// RGB888 image decoded from one (Frame::jpeg), the packed bytes as they are (".raw") for YUYV,
// NV12, SRGGB8 and for any buffer that does not fill its width x height (a corrupt frame is kept
// byte for byte).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/pixel_format.h"

namespace px::capture {

enum class FrameFileType { kPng, kJpeg, kRaw };

// True for the formats PNG can hold exactly (RGB888, BGR888, GRAY8).
bool PngCanHold(PixelFormat format);
// A frame with its camera's JPEG (Frame::jpeg) is stored as that JPEG; else PNG where it can hold
// the image exactly, else raw.
FrameFileType ChooseFrameFileType(const RawImage& image, bool has_jpeg = false);
std::string_view FrameFileExtension(FrameFileType type);  // ".png", ".jpg", ".raw"
// "frame_0003.png" -> kPng; INVALID_ARGUMENT for any other extension.
StatusOr<FrameFileType> FrameFileTypeOf(std::string_view file_name);

// The file content for `image`. PNG needs a complete image of a format PngCanHold.
StatusOr<std::vector<uint8_t>> EncodeFrameFile(const RawImage& image, FrameFileType type);

// Decodes a PNG file back into the tightly packed bytes of a `format` image of the given size.
// Errors (without the file name; the caller adds it) say what is wrong: not a PNG, truncated,
// wrong channel count or depth, or a size differing from width x height.
StatusOr<std::vector<uint8_t>> DecodePngFrame(std::span<const uint8_t> file, PixelFormat format, int width, int height);

// Decodes a JPEG frame file into the tightly packed RGB888 bytes of a width x height image, upright
// by its EXIF orientation. Errors as DecodePngFrame's.
StatusOr<std::vector<uint8_t>> DecodeJpegFrame(std::span<const uint8_t> file, int width, int height);

}  // namespace px::capture
