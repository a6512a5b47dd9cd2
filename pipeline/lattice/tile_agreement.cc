#include "pipeline/lattice/tile_agreement.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace px::lattice {
namespace {

// Tiles are compared at this many pixels on their longer side: the structure that tells parts of
// a scene apart is coarse, a tile's turn or unequal size moves it by less than a pixel there, and
// the shift search stays cheap.
constexpr int kCompareSizePx = 32;
constexpr double kTrimOfTile = 0.1;
constexpr double kMaxShiftOfTile = 1.0 / 6.0;

// The tile edges along one axis: 0, the gaps, `size`.
std::vector<double> Edges(const std::vector<double>& gaps, int size) {
  std::vector<double> edges{0.0};
  edges.insert(edges.end(), gaps.begin(), gaps.end());
  edges.push_back(size);
  return edges;
}

// Normalised cross-correlation of a and b where a is shifted by (dx, dy) over b.
double ShiftedNcc(const cv::Mat& a, const cv::Mat& b, int dx, int dy) {
  const int w = a.cols - std::abs(dx), h = a.rows - std::abs(dy);
  const cv::Mat pa = a(cv::Rect(std::max(0, dx), std::max(0, dy), w, h));
  const cv::Mat pb = b(cv::Rect(std::max(0, -dx), std::max(0, -dy), w, h));
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  for (int y = 0; y < h; ++y) {
    const float* ra = pa.ptr<float>(y);
    const float* rb = pb.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      sa += ra[x];
      sb += rb[x];
      saa += ra[x] * ra[x];
      sbb += rb[x] * rb[x];
      sab += ra[x] * rb[x];
    }
  }
  const double n = static_cast<double>(w) * h;
  const double va = saa - sa * sa / n, vb = sbb - sb * sb / n;
  if (va <= 1e-9 || vb <= 1e-9) return 0;
  return (sab - sa * sb / n) / std::sqrt(va * vb);
}

// A tile's picture as its derivatives across and along the rows: exposure and smooth vignetting
// barely touch them, and a line across the whole frame (a horizon, a table's edge), which two
// halves of one photo share, agrees in only one of them.
struct TilePicture {
  cv::Mat dx, dy;
};

// Both derivatives' correlation, the worse of the two, at the best shift.
double BestShiftedAgreement(const TilePicture& a, const TilePicture& b) {
  const int sx = static_cast<int>(kMaxShiftOfTile * a.dx.cols), sy = static_cast<int>(kMaxShiftOfTile * a.dx.rows);
  double best = -1;
  for (int dy = -sy; dy <= sy; ++dy) {
    for (int dx = -sx; dx <= sx; ++dx) {
      const double across = ShiftedNcc(a.dx, b.dx, dx, dy);
      if (across <= best) continue;
      best = std::max(best, std::min(across, ShiftedNcc(a.dy, b.dy, dx, dy)));
    }
  }
  return best;
}

}  // namespace

double TileAgreement(const cv::Mat& grey,
                     const std::vector<double>& x_gaps,
                     const std::vector<double>& y_gaps,
                     double stop_below) {
  const std::vector<double> xs = Edges(x_gaps, grey.cols), ys = Edges(y_gaps, grey.rows);
  const int cols = static_cast<int>(xs.size()) - 1, rows = static_cast<int>(ys.size()) - 1;
  if (rows * cols < 2) return 1;
  std::vector<cv::Rect> rects;
  cv::Size crop(grey.cols, grey.rows);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double tw = xs[c + 1] - xs[c], th = ys[r + 1] - ys[r];
      const int x0 = static_cast<int>(std::ceil(xs[c] + kTrimOfTile * tw));
      const int y0 = static_cast<int>(std::ceil(ys[r] + kTrimOfTile * th));
      const int x1 = static_cast<int>(std::floor(xs[c + 1] - kTrimOfTile * tw));
      const int y1 = static_cast<int>(std::floor(ys[r + 1] - kTrimOfTile * th));
      const cv::Rect rect = cv::Rect(x0, y0, x1 - x0, y1 - y0) & cv::Rect(0, 0, grey.cols, grey.rows);
      if (rect.width < 8 || rect.height < 8) return kTilesTooThin;
      rects.push_back(rect);
      crop.width = std::min(crop.width, rect.width);
      crop.height = std::min(crop.height, rect.height);
    }
  }
  const double shrink = std::min(1.0, static_cast<double>(kCompareSizePx) / std::max(crop.width, crop.height));
  const cv::Size common(std::max(8, static_cast<int>(std::lround(crop.width * shrink))),
                        std::max(8, static_cast<int>(std::lround(crop.height * shrink))));
  std::vector<TilePicture> tiles;
  for (const cv::Rect& rect : rects) {
    // The same number of pixels from each tile's centre: tiles of unequal size keep one scale.
    const cv::Rect centred(
        rect.x + (rect.width - crop.width) / 2, rect.y + (rect.height - crop.height) / 2, crop.width, crop.height);
    cv::Mat tile;
    cv::resize(grey(centred), tile, common, 0, 0, cv::INTER_AREA);
    TilePicture picture;
    cv::Sobel(tile, picture.dx, CV_32F, 1, 0);
    cv::Sobel(tile, picture.dy, CV_32F, 0, 1);
    tiles.push_back(picture);
  }
  double agreement = 1;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const TilePicture& tile = tiles[r * cols + c];
      if (c + 1 < cols) agreement = std::min(agreement, BestShiftedAgreement(tile, tiles[r * cols + c + 1]));
      if (r + 1 < rows) agreement = std::min(agreement, BestShiftedAgreement(tile, tiles[(r + 1) * cols + c]));
      if (agreement < stop_below) return agreement;
    }
  }
  return agreement;
}

cv::Mat CoarseWorkingFrame(const cv::Mat& grey, int working_size_px) {
  const double scale = std::min(1.0, static_cast<double>(working_size_px) / std::max(grey.cols, grey.rows));
  cv::Mat small, work;
  if (scale < 1.0) {
    cv::resize(grey, small, cv::Size(), scale, scale, cv::INTER_AREA);
  } else {
    small = grey;
  }
  small.convertTo(work, CV_32F);
  cv::GaussianBlur(work, work, cv::Size(0, 0), 1.0);
  return work;
}

EqualCut FindEqualCut(const cv::Mat& grey, cv::Size found, int max_per_axis, int rows, int cols, bool measure_fully) {
  found = cv::Size(std::max(1, found.width), std::max(1, found.height));
  std::vector<EqualCut> cuts;
  for (int r = found.height; r <= max_per_axis; r += found.height) {
    for (int c = found.width; c <= max_per_axis; c += found.width) {
      if (r * c <= found.area() || (rows > 0 && r != rows) || (cols > 0 && c != cols)) continue;
      const double aspect = (static_cast<double>(grey.cols) / c) / (static_cast<double>(grey.rows) / r);
      if (aspect > kMaxEqualTileAspect || aspect < 1.0 / kMaxEqualTileAspect) continue;
      cuts.push_back({r, c});
    }
  }
  // Most tiles first: a lattice's tiles agree, and so do the blocks of several of them.
  std::stable_sort(
      cuts.begin(), cuts.end(), [](const EqualCut& a, const EqualCut& b) { return a.rows * a.cols > b.rows * b.cols; });
  EqualCut none;
  none.tried = static_cast<int>(cuts.size());
  for (EqualCut& cut : cuts) {
    cut.tried = none.tried;
    std::vector<double> x_gaps, y_gaps;
    for (int c = 1; c < cut.cols; ++c) x_gaps.push_back(static_cast<double>(grey.cols) * c / cut.cols);
    for (int r = 1; r < cut.rows; ++r) y_gaps.push_back(static_cast<double>(grey.rows) * r / cut.rows);
    cut.agreement = TileAgreement(grey, x_gaps, y_gaps, measure_fully ? -1.0 : kSameSceneAgreement);
    if (cut.agreement >= kSameSceneAgreement) return cut;
    none.agreement = std::max(none.agreement, cut.agreement);
  }
  return none;
}

}  // namespace px::lattice
