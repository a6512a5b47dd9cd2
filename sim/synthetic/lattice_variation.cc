#include "sim/synthetic/lattice_variation.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "pipeline/core/check.h"

namespace px::sim {
namespace {

std::string TileName(const Tile& t) { return "tile (" + std::to_string(t.row) + "," + std::to_string(t.col) + ")"; }

// The axis-aligned box around a tile's turned corners, grown by `margin_px`.
cv::Rect2d TurnedBounds(const Tile& tile, double margin_px) {
  const std::array<cv::Point2d, 4> corners = TileCorners(tile);
  double x0 = corners[0].x, x1 = x0, y0 = corners[0].y, y1 = y0;
  for (const cv::Point2d& p : corners) {
    x0 = std::min(x0, p.x);
    x1 = std::max(x1, p.x);
    y0 = std::min(y0, p.y);
    y1 = std::max(y1, p.y);
  }
  return {x0 - margin_px, y0 - margin_px, x1 - x0 + 2 * margin_px, y1 - y0 + 2 * margin_px};
}

}  // namespace

Status LatticeVariation::Validate() const {
  std::ostringstream error;
  if (!(max_offset_px >= 0 && max_offset_px <= 64))
    error << "max_offset_px " << max_offset_px << " is outside [0, 64]";
  else if (!(max_size_change >= 0 && max_size_change <= 0.2))
    error << "max_size_change " << max_size_change << " is outside [0, 0.2]";
  else if (!(max_rotation_deg >= 0 && max_rotation_deg <= 5))
    error << "max_rotation_deg " << max_rotation_deg << " is outside [0, 5]";
  else if (outer_margin_px < -1)
    error << "outer_margin_px " << outer_margin_px << " is below -1";
  if (error.str().empty()) return OkStatus();
  return InvalidArgumentError("lattice variation: " + error.str());
}

StatusOr<LatticeLayout> VariedLayout(const SimCameraSpec& spec, const LatticeVariation& variation) {
  PX_RETURN_IF_ERROR(spec.Validate());
  PX_RETURN_IF_ERROR(variation.Validate());
  LatticeLayout layout = spec.Layout();
  const int margin = variation.outer_margin_px < 0 ? spec.gap_px : variation.outer_margin_px;
  const int shift = margin - spec.gap_px;
  layout.sensor_width += 2 * shift;
  layout.sensor_height += 2 * shift;
  cv::RNG rng(variation.seed * 0x9e3779b97f4a7c15ULL + 7);
  for (Tile& tile : layout.tiles) {
    const double cx = tile.rect.x + shift + 0.5 * tile.rect.width + rng.uniform(-1.0, 1.0) * variation.max_offset_px;
    const double cy = tile.rect.y + shift + 0.5 * tile.rect.height + rng.uniform(-1.0, 1.0) * variation.max_offset_px;
    const int w =
        static_cast<int>(std::lround(tile.rect.width * (1 + rng.uniform(-1.0, 1.0) * variation.max_size_change)));
    const int h =
        static_cast<int>(std::lround(tile.rect.height * (1 + rng.uniform(-1.0, 1.0) * variation.max_size_change)));
    tile.rect =
        cv::Rect(static_cast<int>(std::lround(cx - 0.5 * w)), static_cast<int>(std::lround(cy - 0.5 * h)), w, h);
    tile.rotation_deg = rng.uniform(-1.0, 1.0) * variation.max_rotation_deg;
  }
  const Status valid = layout.Validate();
  if (!valid.ok()) return InvalidArgumentError("varied lattice: " + valid.message());
  // Turned tiles must stay on the sensor and at least a pixel apart.
  const cv::Rect2d sensor(0, 0, layout.sensor_width, layout.sensor_height);
  for (size_t i = 0; i < layout.tiles.size(); ++i) {
    const cv::Rect2d bounds = TurnedBounds(layout.tiles[i], 0.5);
    if ((bounds & sensor) != bounds) {
      return InvalidArgumentError("varied lattice: " + TileName(layout.tiles[i]) + " turned by " +
                                  std::to_string(layout.tiles[i].rotation_deg) + " deg leaves the sensor");
    }
    for (size_t j = 0; j < i; ++j) {
      if ((bounds & TurnedBounds(layout.tiles[j], 0.5)).area() > 0) {
        return InvalidArgumentError("varied lattice: " + TileName(layout.tiles[i]) + " and " +
                                    TileName(layout.tiles[j]) + " touch once varied (gap_px " +
                                    std::to_string(spec.gap_px) + " is too small for the variation)");
      }
    }
  }
  return layout;
}

cv::Mat ComposeSensorOnLayout(const SimCameraSpec& spec,
                              const LatticeLayout& layout,
                              const std::vector<ViewTruth>& views,
                              const std::vector<double>& exposure_gains,
                              uint64_t noise_seed) {
  PX_CHECK(static_cast<int>(views.size()) == layout.NumViews() &&
           static_cast<int>(exposure_gains.size()) == layout.NumViews())
      << "got " << views.size() << " views and " << exposure_gains.size() << " gains for " << layout.NumViews()
      << " tiles";
  // The spec's own composition for its own tile size, then each tile moved where the layout puts it.
  const cv::Mat regular = ComposeSensorBgr(spec, views, exposure_gains, noise_seed);
  const LatticeLayout regular_layout = spec.Layout();
  cv::Mat sensor(layout.sensor_height, layout.sensor_width, CV_32FC3);
  cv::RNG gap_rng(noise_seed ^ 0x5eed);
  gap_rng.fill(sensor, cv::RNG::NORMAL, cv::Scalar::all(spec.gap_level), cv::Scalar::all(spec.gap_noise_sigma));
  const cv::Rect frame(0, 0, layout.sensor_width, layout.sensor_height);
  for (int i = 0; i < layout.NumViews(); ++i) {
    const Tile& tile = layout.tiles[i];
    cv::Mat stored;  // the tile as it lies on the sensor, before its rotation
    cv::resize(regular(regular_layout.tiles[i].rect), stored, tile.rect.size(), 0, 0, cv::INTER_AREA);
    stored.convertTo(stored, CV_32FC3);
    const cv::Rect roi = cv::Rect(TurnedBounds(tile, 2.0)) & frame;
    cv::Matx23d m = SensorFromTile(tile);
    m(0, 2) -= roi.x;
    m(1, 2) -= roi.y;
    // Bilinear with a zero border: at the tile's outline the value fades with its coverage, so
    // blending by the warped coverage gives a sub-pixel (anti-aliased) edge.
    cv::Mat value, coverage;
    cv::warpAffine(stored, value, cv::Mat(m), roi.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar::all(0));
    cv::warpAffine(cv::Mat(stored.size(), CV_32FC3, cv::Scalar::all(1)),
                   coverage,
                   cv::Mat(m),
                   roi.size(),
                   cv::INTER_LINEAR,
                   cv::BORDER_CONSTANT,
                   cv::Scalar::all(0));
    cv::Mat background = sensor(roi);
    cv::Mat blended = background.mul(cv::Scalar::all(1) - coverage) + value;
    blended.copyTo(background);
  }
  cv::Mat bgr;
  sensor.convertTo(bgr, CV_8UC3);
  return bgr;
}

}  // namespace px::sim
