// How one frame's bytes are stored in a recording: lossless PNG for complete RGB888, BGR888 and
// GRAY8 images (decoding gives back the exact bytes), the packed bytes as they are (".raw") for
// YUYV, NV12, SRGGB8 and for any buffer that does not fill its width x height (a corrupt frame
// is kept byte for byte).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/pixel_format.h"

namespace px::replay {

enum class FrameFileType { kPng, kRaw };

// True for the formats PNG can hold exactly (RGB888, BGR888, GRAY8).
bool PngCanHold(PixelFormat format);
FrameFileType ChooseFrameFileType(const RawImage& image);
std::string_view FrameFileExtension(FrameFileType type);  // ".png", ".raw"
// "frame_0003.png" -> kPng; INVALID_ARGUMENT for any other extension.
StatusOr<FrameFileType> FrameFileTypeOf(std::string_view file_name);

// The file content for `image`. PNG needs a complete image of a format PngCanHold.
StatusOr<std::vector<uint8_t>> EncodeFrameFile(const RawImage& image, FrameFileType type);

// Decodes a PNG file back into the tightly packed bytes of a `format` image of the given size.
// Errors (without the file name; the caller adds it) say what is wrong: not a PNG, truncated,
// wrong channel count or depth, or a size differing from width x height.
StatusOr<std::vector<uint8_t>> DecodePngFrame(std::span<const uint8_t> file, PixelFormat format, int width,
                                              int height);

}  // namespace px::replay
