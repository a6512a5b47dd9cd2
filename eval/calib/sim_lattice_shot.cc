#include "eval/calib/sim_lattice_shot.h"

#include <chrono>
#include <fstream>

#include "pipeline/core/pixel_format.h"
#include "pipeline/lattice/split_lattice.h"
#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/synthetic_source.h"

namespace px::eval {

SimCameraSpec RealisticSpec(SimCameraSpec spec, uint64_t perturb_lenses_seed) {
  spec.noise_sigma = 2.0;
  spec.vignetting = 0.3;
  spec.exposure_spread = 0.05;
  spec.perturb_lenses_seed = perturb_lenses_seed;
  return spec;
}

SimCameraSpec HalfSize(SimCameraSpec spec) {
  spec.tile_width /= 2;
  spec.tile_height /= 2;
  spec.focal_px /= 2;
  spec.gap_px /= 2;
  return spec;
}

StatusOr<LatticeShot> CaptureLatticeShot(const SimCameraSpec& spec, const std::string& scene, uint64_t seed) {
  SyntheticSourceOptions options;
  options.camera = spec;
  options.scene_file =
      scene.find('/') != std::string::npos ? std::filesystem::path(scene) : sim::ScenesDir() / (scene + ".json");
  options.seed = seed;
  PX_ASSIGN_OR_RETURN(auto source, MakeSyntheticSource(options));
  SourceConfig wanted, granted;
  wanted.pixel_format = PixelFormat::kRgb888;
  PX_ASSIGN_OR_RETURN(ConfigureResult configured, source->Configure(wanted, &granted));
  (void)configured;
  PX_ASSIGN_OR_RETURN(FrameSet capture, source->Next(std::chrono::milliseconds(600000)));
  PX_ASSIGN_OR_RETURN(sim::GroundTruth truth, LastGroundTruth(*source));
  PX_ASSIGN_OR_RETURN(cv::Mat sensor, ToBgr(capture.frames.at(0).image));
  LatticeShot shot;
  shot.factory = *source->Describe().rig;
  shot.truth = truth.rig;
  PX_ASSIGN_OR_RETURN(shot.tiles, SplitLattice(sensor, shot.factory.lattice));
  shot.sensor = sensor;
  return shot;
}

void WritePlaneScene(const std::filesystem::path& file, double distance_m, const std::string& material_json) {
  const double size = 4.0 * distance_m;  // fills every lens (field of view under 60 degrees)
  std::ofstream out(file);
  out << "{\"name\": \"plane\", \"objects\": [{\"type\": \"plane\", \"centre_m\": [0, 0, " << distance_m
      << "], \"width_m\": " << size << ", \"height_m\": " << size << ", \"material\": " << material_json << "}]}\n";
}

}  // namespace px::eval
