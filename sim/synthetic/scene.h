// A synthetic scene: finite textured planes, boxes and spheres under one soft directional
// light, in world (= rig) coordinates: metres, x right, y down, z forward from the camera.
// Shading is view-independent (Lambertian), so every lens sees the same colour at a point:
// the property multi-view ground truth relies on. Scenes are read from JSON (scene_json.h).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "sim/synthetic/texture.h"

namespace px::sim {

enum class MaterialKind {
  kFlat,      // one colour
  kChecker,   // two colours in squares of scale_m
  kNoise,     // fractal value noise between two (optionally three) colours
  kGradient,  // linear ramp between two colours over scale_m along `direction`
  kTexture,   // an image, stretched over the surface or repeated every tile_m
};

struct Material {
  std::string name;
  MaterialKind kind = MaterialKind::kFlat;
  cv::Vec3f bgr_a{128, 128, 128};  // colours in 8-bit levels, BGR order
  cv::Vec3f bgr_b{64, 64, 64};
  cv::Vec3f bgr_c{0, 0, 0};         // noise: a third colour blended in by an independent field
  float mix_c = 0.0f;               // noise: weight of bgr_c, [0, 1]
  double scale_m = 0.1;             // checker square, noise's largest wavelength, gradient length
  int octaves = 5;                  // noise layers, each half the previous wavelength
  double persistence = 0.5;         // noise: amplitude ratio of successive layers, (0, 1]; higher = more fine detail
  double contrast = 1.0;            // noise: stretch around the mean (fractal sums cluster at 0.5)
  uint32_t seed = 0;                // noise field
  Eigen::Vector2d direction{1, 0};  // gradient direction in surface coordinates (unit)
  std::shared_ptr<const MipTexture> texture;
  Eigen::Vector2d tile_m{0, 0};  // texture repeat size on the surface; 0 = stretch once
  bool lit = true;               // false: ignore the light (photos keep their own shading)
};

// Light arriving from direction `towards_light` (unit, from the surface to the light).
struct Light {
  Eigen::Vector3d towards_light = Eigen::Vector3d(-0.3, -0.6, -1.0).normalized();
  double ambient = 0.55;  // gain on unlit-facing surfaces
  double diffuse = 0.45;  // extra gain where the surface faces the light
};

// A finite rectangle, visible from both sides. Texture u runs along `right`, v along `down`.
struct Plane {
  std::string name;
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal{0, 0, -1};  // unit; the front face looks along it
  Eigen::Vector3d right{1, 0, 0};    // unit, in the plane
  Eigen::Vector3d down{0, 1, 0};     // unit, in the plane: right x normal
  double width_m = 1.0;              // extent along right
  double height_m = 1.0;             // extent along down
  int material = 0;                  // index into Scene::materials
};

// An oriented box; each face carries the whole material (a texture stretched per face).
struct Box {
  std::string name;
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d world_from_box = Eigen::Matrix3d::Identity();  // columns: box axes in world
  Eigen::Vector3d half_size_m{0.5, 0.5, 0.5};
  int material = 0;
};

struct Sphere {
  std::string name;
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();
  double radius_m = 0.5;
  int material = 0;
};

// An infinite plane z = distance_m (world) facing the camera: "the far backdrop".
struct Backdrop {
  double distance_m = 20.0;
  int material = 0;
};

struct Scene {
  std::string name;
  std::filesystem::path file;         // where it was read from (empty if built in code)
  cv::Vec3f background_bgr{0, 0, 0};  // rays that hit nothing (depth 0)
  std::optional<Backdrop> backdrop;   // if set, rays that hit nothing else hit this
  Light light;
  std::vector<Material> materials;
  std::vector<Plane> planes;
  std::vector<Box> boxes;
  std::vector<Sphere> spheres;
  std::vector<std::string> warnings;  // degradations while loading (texture fallbacks)

  // Index of the material named `name`, or -1.
  int FindMaterial(const std::string& name) const;
};

}  // namespace px::sim
