// Simulated hand-held image sets with known cameras for the structure-from-motion tests:
// still_life (or any scene JSON) rendered through a 640x480 pinhole from given centres and turns,
// with sensor noise; and the figures of a reconstruction against the truth.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "pipeline/calib/incremental_sfm.h"
#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"

namespace px::sim_calib {

struct ImageSet {
  std::vector<calib::SfmImage> images;
  std::vector<Rigid3> truth;
  CameraModel camera;
};

// `centres_m` and turns (degrees about x, y, z) per view, all looking down +z at `scene_name`
// (a scene in sim/scenes, or a path to a scene JSON).
ImageSet Render(const std::string& scene_name,
                const std::vector<Eigen::Vector3d>& centres_m,
                const std::vector<Eigen::Vector3d>& turns_deg,
                bool known_focal);

// The same through one camera per view (e.g. a grid of cameras with shifted principal points);
// with `known_intrinsics` every image carries its own camera and camera id.
ImageSet RenderCameras(const std::string& scene_name,
                       const std::vector<CameraModel>& cameras,
                       const std::vector<Rigid3>& cam_from_world,
                       bool known_intrinsics);

// Four hand-held shots 8 cm apart (about 3 inches), each turned by up to 2 degrees (sim::HandHeldPlaces()).
ImageSet HandHeld(bool known_focal, const std::string& scene = "still_life");

struct Figures {
  double rotation_deg = 0, centre = 0, focal = 0;
};

Figures Compare(const calib::SfmResult& result, const ImageSet& set);
void Print(const char* name, const calib::SfmResult& result, const Figures& figures);

}  // namespace px::sim_calib
