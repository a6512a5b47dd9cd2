// The byte-level damage behind each fault, on one frame: what a short DMA transfer, a bit error,
// a covered lens or a renegotiated format does to the buffer a camera hands over.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>

#include "pipeline/core/frame_set.h"

namespace px::faults {

// Keeps the first floor(keep * size) bytes; marks the frame corrupt, naming what arrived.
void TruncateFrame(double keep, Frame* frame);

// XORs `count` bytes at seeded offsets with non-zero values, so every one really changes.
// flagged: the frame is marked corrupt (a driver that saw the error); else it stays as it was.
void GarbleFrame(int count, bool flagged, uint64_t seed, Frame* frame);

// Image set: the image never arrived (status dropped, no bytes, size and format kept).
void DropFrame(Frame* frame);

// Lattice: paints `rect` (sensor pixels) one flat dark level in the frame's own pixel format, as
// a covered or dead lens shows; the frame status stays ok (the camera cannot tell).
// INVALID_ARGUMENT when the rect leaves the image or the buffer is short.
Status BlankRect(const cv::Rect& rect, RawImage* image);

// Re-encodes the image in `format` (unchanged when nullopt) at width x height (0 = unchanged);
// the frame's status stays ok: the camera delivered it so, and it is the caller's check
// (CheckFrameSet) that notices. Errors name the impossible size or format.
Status ReformatFrame(std::optional<PixelFormat> format, int width, int height, Frame* frame);

}  // namespace px::faults
