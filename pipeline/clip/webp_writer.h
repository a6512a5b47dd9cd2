// Clip output as an animated WebP (libavcodec's libwebp_anim encoder; webp muxer). Use OpenClipWriter (clip_writer.h),
// which validates the options.
#pragma once

#include <filesystem>
#include <memory>

#include "pipeline/clip/clip_writer.h"

namespace px::clip {

StatusOr<std::unique_ptr<ClipWriter>> OpenWebpWriter(const std::filesystem::path& path,
                                                     int width,
                                                     int height,
                                                     const ClipOptions& options);

}  // namespace px::clip
