// Clip output as an animated GIF (libavcodec's gif encoder, PAL8 frames with an adaptive palette; gif muxer). Use
// OpenClipWriter (clip_writer.h), which validates the options.
#pragma once

#include <filesystem>
#include <memory>

#include "pipeline/clip/clip_writer.h"

namespace px::clip {

StatusOr<std::unique_ptr<ClipWriter>> OpenGifWriter(const std::filesystem::path& path,
                                                    int width,
                                                    int height,
                                                    const ClipOptions& options);

}  // namespace px::clip
