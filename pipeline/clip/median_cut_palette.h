// An adaptive palette for GIF frames: Heckbert's median cut over a histogram of 5 bits per
// channel, each entry the mean of the pixels in its box, and a lookup table from every 6-bit
// colour to its nearest entry (so colours absent when the palette was built still map well, and
// the lookup's own 4-level steps stay below the dither's 16). The table is filled lazily, for
// the colours frames actually hold: a frame uses a few thousand of its 2^18 cells.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

namespace px::clip {

class MedianCutPalette {
 public:
  // Builds at most `max_colours` ([1, 256]) entries from every `step`-th pixel of `bgr` (CV_8UC3)
  // in each direction.
  static MedianCutPalette Build(const cv::Mat& bgr, int max_colours, int step);
  MedianCutPalette() = default;
  MedianCutPalette(MedianCutPalette&&) = default;
  MedianCutPalette& operator=(MedianCutPalette&&) = default;

  const std::vector<cv::Vec3b>& colours() const { return colours_; }  // BGR
  // Writes each pixel's palette index into `indices` (CV_8U, the size of `bgr`). With `dither`,
  // an ordered 4x4 Bayer pattern of +-8 levels is added first, breaking the bands a 255-colour
  // palette leaves in smooth gradients (and, unlike error diffusion, it stays still from frame
  // to frame, so the GIF encoder's frame differencing keeps working).
  void Map(const cv::Mat& bgr, bool dither, cv::Mat* indices) const;
  // Mean squared error per channel of mapping every `step`-th pixel without dither.
  double MeanSquaredError(const cv::Mat& bgr, int step) const;

 private:
  // The entry nearest to the centre of 6-bit cell `cell`, from the table or computed into it.
  uint8_t Nearest(int cell) const;

  std::vector<cv::Vec3b> colours_;
  // 2^18 entries: 6-bit (b, g, r) -> nearest palette index, or kUnknown. Atomic because Map
  // fills it from several threads at once (each writes the same value for a cell).
  std::unique_ptr<std::atomic<uint16_t>[]> nearest_;
};

}  // namespace px::clip
