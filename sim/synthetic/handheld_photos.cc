#include "sim/synthetic/handheld_photos.h"

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string_view>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/option_range.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/io/durable_file.h"
#include "sim/synthetic/exif_jpeg.h"
#include "sim/synthetic/ray_caster.h"
#include "sim/synthetic/scene_json.h"

namespace px::sim {
namespace {

constexpr std::string_view kPhotoOptions = "hand-held photo options";

cv::Mat WithNoise(const cv::Mat& bgr, double sigma, uint64_t seed) {
  if (sigma <= 0) return bgr;
  cv::Mat noise(bgr.size(), CV_16SC3);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0, sigma);
  cv::Mat wide, out;
  bgr.convertTo(wide, CV_16SC3);
  wide += noise;
  wide.convertTo(out, CV_8UC3);
  return out;
}

}  // namespace

const std::vector<HandHeldPlace>& HandHeldPlaces() {
  static const std::vector<HandHeldPlace> places = {{{-0.12, 0.0, 0.0}, {0.5, 1.5, -0.3}},
                                                    {{-0.04, 0.01, 0.005}, {-0.8, 0.4, 0.6}},
                                                    {{0.04, -0.005, -0.01}, {1.2, -1.0, 0.2}},
                                                    {{0.12, 0.008, 0.0}, {-0.3, -2.0, -0.7}}};
  return places;
}

Rigid3 CamFromWorldAt(const HandHeldPlace& place) {
  const double k = M_PI / 180.0;
  const Eigen::Quaterniond rotation(Eigen::AngleAxisd(place.turn_deg.x() * k, Eigen::Vector3d::UnitX()) *
                                    Eigen::AngleAxisd(place.turn_deg.y() * k, Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(place.turn_deg.z() * k, Eigen::Vector3d::UnitZ()));
  return Rigid3(rotation, -(rotation * place.centre_m));
}

Status HandHeldPhotoOptions::Validate() const {
  if (width < 64 || width > 16384) return OptionOutOfRange(kPhotoOptions, "width", width, "[64, 16384]");
  if (height < 64 || height > 16384) return OptionOutOfRange(kPhotoOptions, "height", height, "[64, 16384]");
  if (focal_px < 0) return OptionOutOfRange(kPhotoOptions, "focal_px", focal_px, "0 (the default) or > 0");
  if (shots < 2 || shots > static_cast<int>(HandHeldPlaces().size()))
    return OptionOutOfRange(kPhotoOptions, "shots", shots, "[2, 4]");
  if (noise_sigma < 0 || noise_sigma > 50)
    return OptionOutOfRange(kPhotoOptions, "noise_sigma", noise_sigma, "[0, 50]");
  if (jpeg_quality < 1 || jpeg_quality > 100) {
    return OptionOutOfRange(kPhotoOptions, "jpeg_quality", jpeg_quality, "[1, 100]");
  }
  if (supersampling < 1 || supersampling > RenderOptions::kMaxSupersampling) {
    return OptionOutOfRange(kPhotoOptions, "supersampling", supersampling, "[1, 8]");
  }
  return OkStatus();
}

StatusOr<std::vector<std::filesystem::path>> WriteHandHeldPhotos(const std::filesystem::path& scene_file,
                                                                 const HandHeldPhotoOptions& options,
                                                                 const std::filesystem::path& folder) {
  PX_RETURN_IF_ERROR(options.Validate());
  PX_ASSIGN_OR_RETURN(const Scene scene, LoadScene(scene_file));
  const double focal_px = options.focal_px > 0 ? options.focal_px : 560.0 * options.width / 640.0;
  const CameraModel camera = CameraModel::Pinhole(options.width, options.height, focal_px);
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) return InternalError(folder.string() + ": cannot create the folder: " + ec.message());
  RenderOptions render;
  render.supersampling = options.supersampling;
  std::vector<std::filesystem::path> paths;
  for (int i = 0; i < options.shots; ++i) {
    PX_ASSIGN_OR_RETURN(RenderedView view, RenderView(scene, camera, CamFromWorldAt(HandHeldPlaces()[i]), render));
    std::vector<uint8_t> jpeg;
    if (!cv::imencode(".jpg",
                      WithNoise(view.bgr, options.noise_sigma, 100 + i),
                      jpeg,
                      {cv::IMWRITE_JPEG_QUALITY, options.jpeg_quality})) {
      return InternalError("shot " + std::to_string(i) + ": the JPEG encoder failed");
    }
    const std::vector<uint8_t> photo = WithExifFocalLength(jpeg, focal_px, options.width, options.height);
    paths.push_back(folder / ("shot_" + std::to_string(i) + ".jpg"));
    PX_RETURN_IF_ERROR(
        WriteFileAtomically(paths.back(), std::string_view(reinterpret_cast<const char*>(photo.data()), photo.size())));
  }
  return paths;
}

}  // namespace px::sim
