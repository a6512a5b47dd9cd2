// A simulated hand-held set as a phone or camera writes it: a scene shot from a few places by
// hand (centres a few centimetres apart, each shot turned by a degree or two), each photo a JPEG
// with its focal length in EXIF. What `parallax clip FOLDER` and the benchmarks read as a user's
// photos, at any resolution (a 12 MP phone's 4000x3000 included).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"

namespace px::sim {

// Where a person stands for a shot (metres) and how far the shot is turned (degrees about x, y,
// z, applied in that order), all looking down +z: the drift of a hand, not a rig.
struct HandHeldPlace {
  Eigen::Vector3d centre_m;
  Eigen::Vector3d turn_deg;
};
// The four shots of a hand-held set, left to right, about 8 cm apart, each turned by up to 2
// degrees (what the structure-from-motion tests, `eval render`'s hand-held group and the
// hand-held photos below are shot from).
const std::vector<HandHeldPlace>& HandHeldPlaces();
Rigid3 CamFromWorldAt(const HandHeldPlace& place);

struct HandHeldPhotoOptions {
  int width = 640;
  int height = 480;
  // Focal length in pixels of the photo's width: the default is the simulated Pop9's field of
  // view (560 px at 640 px wide), scaled with the width.
  double focal_px = 0;
  int shots = 4;             // 2..4: the first of HandHeldPlaces()
  double noise_sigma = 2.0;  // Gaussian sensor noise, 8-bit levels
  int jpeg_quality = 92;
  int supersampling = 1;  // rays per pixel side; 1 is plenty at a phone's resolution
  Status Validate() const;
};

// Renders `scene_file` (a scene JSON) as `options.shots` photos and writes them into `folder`
// (created) as shot_0.jpg, shot_1.jpg, ...; returns their paths. Errors: the scene's, bad
// options (naming the field), a file that cannot be written.
StatusOr<std::vector<std::filesystem::path>> WriteHandHeldPhotos(const std::filesystem::path& scene_file,
                                                                 const HandHeldPhotoOptions& options,
                                                                 const std::filesystem::path& folder);

}  // namespace px::sim
