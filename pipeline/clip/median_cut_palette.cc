#include "pipeline/clip/median_cut_palette.h"

#include <algorithm>
#include <array>
#include <limits>
#include <opencv2/core/utility.hpp>

#include "pipeline/core/check.h"

namespace px::clip {
namespace {

// The histogram the boxes are cut from: 5 bits per channel.
constexpr int kBins = 1 << 15;
inline int BinOf(int b, int g, int r) { return ((b >> 3) << 10) | ((g >> 3) << 5) | (r >> 3); }
inline int Channel(int bin, int axis) { return (bin >> (10 - 5 * axis)) & 31; }  // axis 0 = b, 1 = g, 2 = r

// The nearest-entry lookup: 6 bits per channel.
constexpr int kCells = 1 << 18;
inline int CellOf(int b, int g, int r) { return ((b >> 2) << 12) | ((g >> 2) << 6) | (r >> 2); }
constexpr uint16_t kUnknown = 0xffff;

struct BinStats {
  int64_t count = 0;
  std::array<int64_t, 3> sum{};  // of b, g, r
};

// A box of occupied bins: bins_[begin, end) of the shared list.
struct Box {
  int begin = 0;
  int end = 0;
  int64_t count = 0;
  int longest_axis = 0;
  int extent = 0;  // along longest_axis, in bins
};

void Measure(const std::vector<int>& bins, const std::vector<BinStats>& stats, Box* box) {
  std::array<int, 3> lo{31, 31, 31};
  std::array<int, 3> hi{0, 0, 0};
  box->count = 0;
  for (int i = box->begin; i < box->end; ++i) {
    box->count += stats[bins[i]].count;
    for (int axis = 0; axis < 3; ++axis) {
      lo[axis] = std::min(lo[axis], Channel(bins[i], axis));
      hi[axis] = std::max(hi[axis], Channel(bins[i], axis));
    }
  }
  box->extent = -1;
  for (int axis = 0; axis < 3; ++axis) {
    if (hi[axis] - lo[axis] > box->extent) {
      box->extent = hi[axis] - lo[axis];
      box->longest_axis = axis;
    }
  }
}

// 4x4 Bayer matrix, centred: -8 .. +7.
constexpr int kBayer[4][4] = {{0, 8, 2, 10}, {12, 4, 14, 6}, {3, 11, 1, 9}, {15, 7, 13, 5}};

}  // namespace

MedianCutPalette MedianCutPalette::Build(const cv::Mat& bgr, int max_colours, int step) {
  PX_CHECK(bgr.type() == CV_8UC3 && !bgr.empty()) << "palette from an empty or non-BGR image";
  PX_CHECK(max_colours >= 1 && max_colours <= 256 && step >= 1) << max_colours << " colours, step " << step;
  std::vector<BinStats> stats(kBins);
  for (int y = 0; y < bgr.rows; y += step) {
    const cv::Vec3b* row = bgr.ptr<cv::Vec3b>(y);
    for (int x = 0; x < bgr.cols; x += step) {
      const cv::Vec3b& p = row[x];
      BinStats& s = stats[BinOf(p[0], p[1], p[2])];
      ++s.count;
      for (int c = 0; c < 3; ++c) s.sum[c] += p[c];
    }
  }
  std::vector<int> bins;
  for (int bin = 0; bin < kBins; ++bin) {
    if (stats[bin].count > 0) bins.push_back(bin);
  }
  std::vector<Box> boxes(1);
  boxes[0].end = static_cast<int>(bins.size());
  Measure(bins, stats, &boxes[0]);
  while (static_cast<int>(boxes.size()) < max_colours) {
    // Split the box whose pixels spread most: population times squared extent (its error scale).
    int chosen = -1;
    double worst = 0;
    for (size_t i = 0; i < boxes.size(); ++i) {
      const double spread = static_cast<double>(boxes[i].count) * boxes[i].extent * boxes[i].extent;
      if (boxes[i].end - boxes[i].begin > 1 && spread > worst) {
        worst = spread;
        chosen = static_cast<int>(i);
      }
    }
    if (chosen < 0) break;  // every box is a single bin
    Box& box = boxes[chosen];
    const int axis = box.longest_axis;
    std::sort(bins.begin() + box.begin, bins.begin() + box.end, [axis](int a, int b) {
      return Channel(a, axis) < Channel(b, axis);
    });
    // The median by pixel count, kept off both ends so each half holds a bin.
    int64_t seen = 0;
    int split = box.begin + 1;
    for (int i = box.begin; i < box.end - 1; ++i) {
      seen += stats[bins[i]].count;
      split = i + 1;
      if (2 * seen >= box.count) break;
    }
    Box upper;
    upper.begin = split;
    upper.end = box.end;
    box.end = split;
    Measure(bins, stats, &box);
    Measure(bins, stats, &upper);
    boxes.push_back(upper);
  }

  MedianCutPalette palette;
  for (const Box& box : boxes) {
    std::array<int64_t, 3> sum{};
    for (int i = box.begin; i < box.end; ++i) {
      for (int c = 0; c < 3; ++c) sum[c] += stats[bins[i]].sum[c];
    }
    cv::Vec3b colour;
    for (int c = 0; c < 3; ++c)
      colour[c] = static_cast<uint8_t>((sum[c] + box.count / 2) / std::max<int64_t>(box.count, 1));
    palette.colours_.push_back(colour);
  }
  palette.nearest_ = std::make_unique<std::atomic<uint16_t>[]>(kCells);
  for (int cell = 0; cell < kCells; ++cell) palette.nearest_[cell].store(kUnknown, std::memory_order_relaxed);
  return palette;
}

uint8_t MedianCutPalette::Nearest(int cell) const {
  const uint16_t known = nearest_[cell].load(std::memory_order_relaxed);
  if (known != kUnknown) return static_cast<uint8_t>(known);
  const int b = ((cell >> 12) & 63) * 4 + 2, g = ((cell >> 6) & 63) * 4 + 2, r = (cell & 63) * 4 + 2;
  int best = 0;
  int best_distance = std::numeric_limits<int>::max();
  for (size_t i = 0; i < colours_.size(); ++i) {
    const cv::Vec3b& c = colours_[i];
    const int db = b - c[0], dg = g - c[1], dr = r - c[2];
    const int distance = db * db + dg * dg + dr * dr;
    if (distance < best_distance) {
      best_distance = distance;
      best = static_cast<int>(i);
    }
  }
  nearest_[cell].store(static_cast<uint16_t>(best), std::memory_order_relaxed);
  return static_cast<uint8_t>(best);
}

void MedianCutPalette::Map(const cv::Mat& bgr, bool dither, cv::Mat* indices) const {
  indices->create(bgr.size(), CV_8U);
  cv::parallel_for_(cv::Range(0, bgr.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const cv::Vec3b* in = bgr.ptr<cv::Vec3b>(y);
      uint8_t* out = indices->ptr<uint8_t>(y);
      for (int x = 0; x < bgr.cols; ++x) {
        const int offset = dither ? kBayer[y & 3][x & 3] - 8 : 0;
        const int b = std::clamp(in[x][0] + offset, 0, 255);
        const int g = std::clamp(in[x][1] + offset, 0, 255);
        const int r = std::clamp(in[x][2] + offset, 0, 255);
        out[x] = Nearest(CellOf(b, g, r));
      }
    }
  });
}

double MedianCutPalette::MeanSquaredError(const cv::Mat& bgr, int step) const {
  double sum = 0;
  int64_t n = 0;
  for (int y = 0; y < bgr.rows; y += step) {
    const cv::Vec3b* row = bgr.ptr<cv::Vec3b>(y);
    for (int x = 0; x < bgr.cols; x += step) {
      const cv::Vec3b& p = row[x];
      const cv::Vec3b& q = colours_[Nearest(CellOf(p[0], p[1], p[2]))];
      for (int c = 0; c < 3; ++c) sum += (p[c] - q[c]) * (p[c] - q[c]);
      ++n;
    }
  }
  return n == 0 ? 0.0 : sum / (3.0 * static_cast<double>(n));
}

}  // namespace px::clip
