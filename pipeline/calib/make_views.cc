#include "pipeline/calib/make_views.h"

#include <chrono>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>

#include "pipeline/core/log.h"
#include "pipeline/core/stage_clock.h"

namespace px {
namespace {

std::string ViewName(ViewId id) { return "view " + std::to_string(id.value); }

}  // namespace

StatusOr<View> MakeView(ViewId id,
                        const cv::Mat& image,
                        const CameraModel& camera,
                        const Rigid3& cam_from_world,
                        const CalibOptions& options,
                        UndistortCache* cache) {
  PX_RETURN_IF_ERROR(options.Validate());
  PX_RETURN_IF_ERROR(camera.Validate().WithContext(ViewName(id)));
  if (image.empty()) return InvalidArgumentError(ViewName(id) + ": image is empty");
  if (image.type() != CV_8UC3) {
    std::ostringstream error;
    error << ViewName(id) << ": image has " << image.channels() << " channels of depth " << image.depth()
          << ", want 8-bit BGR (CV_8UC3)";
    return InvalidArgumentError(error.str());
  }
  if (image.cols != camera.width || image.rows != camera.height) {
    std::ostringstream error;
    error << ViewName(id) << ": image is " << image.cols << "x" << image.rows << ", lens intrinsics are for "
          << camera.width << "x" << camera.height;
    return InvalidArgumentError(error.str());
  }
  if (!cam_from_world.translation.allFinite() || !cam_from_world.rotation.coeffs().allFinite()) {
    return InvalidArgumentError(ViewName(id) + ": pose is not finite");
  }

  View view;
  view.id = id;
  view.camera = camera.WithoutDistortion();
  view.cam_from_world = cam_from_world;
  if (!camera.HasDistortion()) {
    view.image = image.clone();
    return view;
  }
  UndistortCache local_cache;
  const UndistortCache::Maps& maps = (cache != nullptr ? cache : &local_cache)->Get(camera);
  const int interpolation =
      options.interpolation == CalibOptions::Interpolation::kCubic ? cv::INTER_CUBIC : cv::INTER_LINEAR;
  // Replicate, not black: undistorted corners that fall outside the tile would otherwise form
  // hard dark edges that later stages mistake for texture.
  cv::remap(image, view.image, maps.map_x, maps.map_y, interpolation, cv::BORDER_REPLICATE);
  return view;
}

StatusOr<std::vector<View>> MakeViews(const std::vector<cv::Mat>& upright_tiles,
                                      const RigCalibration& rig,
                                      const CalibOptions& options,
                                      UndistortCache* cache) {
  const auto start = std::chrono::steady_clock::now();
  PX_RETURN_IF_ERROR(options.Validate());
  PX_RETURN_IF_ERROR(rig.Validate());
  if (static_cast<int>(upright_tiles.size()) != rig.NumViews()) {
    return InvalidArgumentError("got " + std::to_string(upright_tiles.size()) + " tiles, rig '" + rig.rig_name +
                                "' calibrates " + std::to_string(rig.NumViews()) + " lenses");
  }
  UndistortCache local_cache;
  UndistortCache* maps = cache != nullptr ? cache : &local_cache;
  std::vector<View> views;
  views.reserve(upright_tiles.size());
  int num_undistorted = 0;
  for (int i = 0; i < rig.NumViews(); ++i) {
    const LensCalibration& lens = rig.lenses[i];
    PX_ASSIGN_OR_RETURN(View view,
                        MakeView(ViewId{i}, upright_tiles[i], lens.camera, lens.cam_from_rig, options, maps));
    num_undistorted += lens.camera.HasDistortion() ? 1 : 0;
    views.push_back(std::move(view));
  }
  const double ms = MsSince(start);
  Logger("calib")->info("made {} views ({} undistorted, {} cached camera maps) in {:.1f} ms",
                        views.size(),
                        num_undistorted,
                        maps->NumCached(),
                        ms);
  return views;
}

}  // namespace px
