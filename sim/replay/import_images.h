// Photos taken elsewhere (a phone, a camera's card) as a recording: one image set, a frame per
// photo, as the USB still camera's source would have delivered them (drivers/ptp): upright,
// full size, RGB888, with the lens's focal length from each JPEG's EXIF for structure from motion.
#pragma once

#include <filesystem>
#include <vector>

#include "pipeline/core/status.h"
#include "sim/replay/recording.h"

namespace px {

// The JPEG and PNG files among `inputs`: files as given (in that order), folders' images sorted
// by name. Errors: an input that does not exist, a file that is not a JPEG or PNG by its name, a
// folder with no images.
StatusOr<std::vector<std::filesystem::path>> ListImages(const std::vector<std::filesystem::path>& inputs);

// One frame per file, in order (sequence = index). Errors name the file: one that cannot be
// decoded; fewer than 2 files (an image set needs two viewpoints). A JPEG whose EXIF cannot be
// read is imported with its focal length unknown (self-calibrated later), and `warnings` says so.
StatusOr<Recording> RecordingFromImages(const std::vector<std::filesystem::path>& files,
                                        std::vector<std::string>* warnings);

}  // namespace px
