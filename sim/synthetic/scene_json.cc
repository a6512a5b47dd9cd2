#include "sim/synthetic/scene_json.h"

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>

#include "pipeline/core/json_fields.h"
#include "pipeline/core/log.h"
#include "sim/synthetic/data_paths.h"

namespace px::sim {
namespace {

using nlohmann::json;
using px::json::FieldPath;
using px::json::IndexPath;

constexpr char kDataPrefix[] = "data:";

// Everything a nested parser needs to know about where it is.
struct Context {
  std::filesystem::path base_dir;
  std::string what;  // the file, for messages and warnings
};

// Rejects keys a typo could have produced; keys starting with "_" or "comment" are notes.
Status CheckKeys(const json& object, const std::string& path, const std::set<std::string>& allowed) {
  for (const auto& [key, value] : object.items()) {
    if (allowed.count(key) || key.rfind('_', 0) == 0 || key.rfind("comment", 0) == 0) continue;
    std::string list;
    for (const std::string& name : allowed) list += (list.empty() ? "" : ", ") + name;
    return InvalidArgumentError(FieldPath(path, key) + ": unknown field (allowed: " + list + ")");
  }
  return OkStatus();
}

StatusOr<Eigen::Vector3d> GetVector3(const json& object, const std::string& key, const std::string& parent) {
  PX_ASSIGN_OR_RETURN(std::vector<double> v, px::json::GetNumbers(object, key, parent, 3));
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

StatusOr<Eigen::Vector3d> GetUnitVector3(const json& object, const std::string& key, const std::string& parent) {
  PX_ASSIGN_OR_RETURN(Eigen::Vector3d v, GetVector3(object, key, parent));
  if (v.norm() < 1e-9) return InvalidArgumentError(FieldPath(parent, key) + ": zero-length direction");
  return v.normalized();
}

// "rgb_a": [r, g, b] in 0..255 -> BGR.
StatusOr<cv::Vec3f> GetRgb(const json& object, const std::string& key, const std::string& parent) {
  PX_ASSIGN_OR_RETURN(std::vector<double> v, px::json::GetNumbers(object, key, parent, 3));
  for (size_t i = 0; i < 3; ++i) {
    if (v[i] < 0 || v[i] > 255) {
      std::ostringstream error;
      error << IndexPath(FieldPath(parent, key), i) << ": " << v[i] << " is not in [0, 255]";
      return InvalidArgumentError(error.str());
    }
  }
  return cv::Vec3f(static_cast<float>(v[2]), static_cast<float>(v[1]), static_cast<float>(v[0]));
}

StatusOr<cv::Vec3f> GetRgbOr(const json& object,
                             const std::string& key,
                             const std::string& parent,
                             const cv::Vec3f& fallback) {
  if (!object.contains(key)) return fallback;
  return GetRgb(object, key, parent);
}

StatusOr<double> GetPositive(const json& object, const std::string& key, const std::string& parent) {
  PX_ASSIGN_OR_RETURN(double value, px::json::GetNumber(object, key, parent));
  if (!(value > 0)) {
    std::ostringstream error;
    error << FieldPath(parent, key) << ": " << value << " is not positive";
    return InvalidArgumentError(error.str());
  }
  return value;
}

StatusOr<double> GetInRange(
    const json& object, const std::string& key, const std::string& parent, double fallback, double lo, double hi) {
  PX_ASSIGN_OR_RETURN(double value, px::json::GetNumberOr(object, key, parent, fallback));
  if (!(value >= lo && value <= hi)) {
    std::ostringstream error;
    error << FieldPath(parent, key) << ": " << value << " is not in [" << lo << ", " << hi << "]";
    return InvalidArgumentError(error.str());
  }
  return value;
}

// Rz * Ry * Rx from degrees: rotate about world x first, then y, then z.
StatusOr<Eigen::Matrix3d> GetRotation(const json& object, const std::string& key, const std::string& parent) {
  if (!object.contains(key)) return Eigen::Matrix3d(Eigen::Matrix3d::Identity());
  PX_ASSIGN_OR_RETURN(Eigen::Vector3d deg, GetVector3(object, key, parent));
  const Eigen::Vector3d rad = deg * (M_PI / 180.0);
  const Eigen::Quaterniond rotation = Eigen::AngleAxisd(rad.z(), Eigen::Vector3d::UnitZ()) *
                                      Eigen::AngleAxisd(rad.y(), Eigen::Vector3d::UnitY()) *
                                      Eigen::AngleAxisd(rad.x(), Eigen::Vector3d::UnitX());
  return rotation.toRotationMatrix();
}

StatusOr<MaterialKind> ParseKind(const json& object, const std::string& path) {
  PX_ASSIGN_OR_RETURN(std::string type, px::json::GetString(object, "type", path));
  if (type == "flat") return MaterialKind::kFlat;
  if (type == "checker") return MaterialKind::kChecker;
  if (type == "noise") return MaterialKind::kNoise;
  if (type == "gradient") return MaterialKind::kGradient;
  if (type == "texture") return MaterialKind::kTexture;
  return InvalidArgumentError(FieldPath(path, "type") + ": '" + type +
                              "' is not one of flat, checker, noise, gradient, texture");
}

// A procedural (non-texture) material.
StatusOr<Material> ParseProcedural(const json& j, const std::string& path, MaterialKind kind) {
  Material m;
  m.kind = kind;
  PX_ASSIGN_OR_RETURN(m.lit, px::json::GetBoolOr(j, "lit", path, true));
  switch (kind) {
    case MaterialKind::kFlat: {
      PX_RETURN_IF_ERROR(CheckKeys(j, path, {"type", "lit", "rgb"}));
      PX_ASSIGN_OR_RETURN(m.bgr_a, GetRgb(j, "rgb", path));
      break;
    }
    case MaterialKind::kChecker: {
      PX_RETURN_IF_ERROR(CheckKeys(j, path, {"type", "lit", "rgb_a", "rgb_b", "square_m"}));
      PX_ASSIGN_OR_RETURN(m.bgr_a, GetRgb(j, "rgb_a", path));
      PX_ASSIGN_OR_RETURN(m.bgr_b, GetRgb(j, "rgb_b", path));
      PX_ASSIGN_OR_RETURN(m.scale_m, GetPositive(j, "square_m", path));
      break;
    }
    case MaterialKind::kNoise: {
      PX_RETURN_IF_ERROR(CheckKeys(j,
                                   path,
                                   {"type",
                                    "lit",
                                    "rgb_a",
                                    "rgb_b",
                                    "rgb_c",
                                    "mix_c",
                                    "scale_m",
                                    "octaves",
                                    "persistence",
                                    "contrast",
                                    "seed"}));
      PX_ASSIGN_OR_RETURN(m.bgr_a, GetRgb(j, "rgb_a", path));
      PX_ASSIGN_OR_RETURN(m.bgr_b, GetRgb(j, "rgb_b", path));
      PX_ASSIGN_OR_RETURN(m.bgr_c, GetRgbOr(j, "rgb_c", path, m.bgr_c));
      PX_ASSIGN_OR_RETURN(double mix_c, GetInRange(j, "mix_c", path, j.contains("rgb_c") ? 0.5 : 0.0, 0, 1));
      m.mix_c = static_cast<float>(mix_c);
      PX_ASSIGN_OR_RETURN(m.scale_m, GetPositive(j, "scale_m", path));
      PX_ASSIGN_OR_RETURN(double octaves, GetInRange(j, "octaves", path, 5, 1, 12));
      if (octaves != std::floor(octaves)) {
        return InvalidArgumentError(FieldPath(path, "octaves") + ": want an integer, got " + std::to_string(octaves));
      }
      m.octaves = static_cast<int>(octaves);
      PX_ASSIGN_OR_RETURN(m.persistence, GetInRange(j, "persistence", path, 0.5, 0.05, 1.0));
      PX_ASSIGN_OR_RETURN(m.contrast, GetInRange(j, "contrast", path, 1.0, 0.0, 20.0));
      PX_ASSIGN_OR_RETURN(int64_t seed, px::json::GetIntegerOr(j, "seed", path, 0));
      m.seed = static_cast<uint32_t>(seed);
      break;
    }
    case MaterialKind::kGradient: {
      PX_RETURN_IF_ERROR(CheckKeys(j, path, {"type", "lit", "rgb_a", "rgb_b", "length_m", "direction"}));
      PX_ASSIGN_OR_RETURN(m.bgr_a, GetRgb(j, "rgb_a", path));
      PX_ASSIGN_OR_RETURN(m.bgr_b, GetRgb(j, "rgb_b", path));
      PX_ASSIGN_OR_RETURN(m.scale_m, GetPositive(j, "length_m", path));
      if (j.contains("direction")) {
        PX_ASSIGN_OR_RETURN(std::vector<double> d, px::json::GetNumbers(j, "direction", path, 2));
        Eigen::Vector2d direction(d[0], d[1]);
        if (direction.norm() < 1e-9) return InvalidArgumentError(FieldPath(path, "direction") + ": zero length");
        m.direction = direction.normalized();
      }
      break;
    }
    case MaterialKind::kTexture:
      PX_CHECK(false) << "texture materials are parsed by ParseTexture";
  }
  return m;
}

std::filesystem::path ResolveTexturePath(const std::string& file, const Context& context) {
  if (file.rfind(kDataPrefix, 0) == 0) return SharedDataDir() / file.substr(sizeof(kDataPrefix) - 1);
  std::filesystem::path path(file);
  return path.is_absolute() ? path : context.base_dir / path;
}

// Reads the image; NOT_FOUND when absent, DATA_LOSS when it does not decode.
StatusOr<cv::Mat> ReadTextureImage(const std::filesystem::path& file) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) return NotFoundError("texture " + file.string() + " not found");
  cv::Mat image;
  try {
    image = cv::imread(file.string(), cv::IMREAD_COLOR);
  } catch (const cv::Exception& e) {
    return DataLossError("texture " + file.string() + " could not be decoded: " + e.what());
  }
  if (image.empty()) return DataLossError("texture " + file.string() + " could not be decoded");
  return image;
}

StatusOr<Material> ParseMaterial(const json& j, const std::string& path, const Context& context, Scene* scene);

// `scene` holds the materials parsed so far (fallbacks may name them) and collects warnings.
StatusOr<Material> ParseTexture(const json& j, const std::string& path, const Context& context, Scene* scene) {
  PX_RETURN_IF_ERROR(CheckKeys(j, path, {"type", "lit", "file", "crop_px", "tile_m", "fallback"}));
  Material m;
  m.kind = MaterialKind::kTexture;
  PX_ASSIGN_OR_RETURN(m.lit, px::json::GetBoolOr(j, "lit", path, true));
  PX_ASSIGN_OR_RETURN(std::string file, px::json::GetString(j, "file", path));
  if (j.contains("tile_m")) {
    PX_ASSIGN_OR_RETURN(std::vector<double> tile, px::json::GetNumbers(j, "tile_m", path, 2));
    if (!(tile[0] > 0 && tile[1] > 0)) return InvalidArgumentError(FieldPath(path, "tile_m") + ": must be positive");
    m.tile_m = Eigen::Vector2d(tile[0], tile[1]);
  }
  std::vector<double> crop;
  if (j.contains("crop_px")) {
    PX_ASSIGN_OR_RETURN(crop, px::json::GetNumbers(j, "crop_px", path, 4));
    for (size_t i = 0; i < 4; ++i) {
      if (crop[i] != std::floor(crop[i]) || crop[i] < 0 || (i >= 2 && crop[i] <= 0)) {
        return InvalidArgumentError(IndexPath(FieldPath(path, "crop_px"), i) +
                                    ": want a non-negative integer (x, y, width, height in pixels)");
      }
    }
  }
  // Parse the fallback first so that a broken fallback is reported even when the file exists.
  std::optional<Material> fallback;
  if (j.contains("fallback")) {
    const std::string fallback_path = FieldPath(path, "fallback");
    const json& f = j["fallback"];
    if (f.is_string()) {
      const int index = scene->FindMaterial(f.get<std::string>());
      if (index < 0) {
        return InvalidArgumentError(fallback_path + ": no procedural material named '" + f.get<std::string>() + "'");
      }
      fallback = scene->materials[index];
    } else {
      PX_ASSIGN_OR_RETURN(Material parsed, ParseMaterial(f, fallback_path, context, scene));
      fallback = parsed;
    }
    if (fallback->kind == MaterialKind::kTexture) {
      return InvalidArgumentError(fallback_path + ": a fallback must be procedural, not a texture");
    }
  }

  const std::filesystem::path resolved = ResolveTexturePath(file, context);
  StatusOr<cv::Mat> image = ReadTextureImage(resolved);
  if (!image.ok()) {
    if (!fallback) return image.status().WithContext(FieldPath(path, "file"));
    const std::string warning = context.what + ": " + FieldPath(path, "file") + ": " + image.status().message() +
                                "; using the fallback material";
    Logger("sim")->warn("{}", warning);
    scene->warnings.push_back(warning);
    return *fallback;
  }
  cv::Mat pixels = *image;
  if (!crop.empty()) {
    const cv::Rect rect(
        static_cast<int>(crop[0]), static_cast<int>(crop[1]), static_cast<int>(crop[2]), static_cast<int>(crop[3]));
    if ((rect & cv::Rect(0, 0, pixels.cols, pixels.rows)) != rect) {
      std::ostringstream error;
      error << FieldPath(path, "crop_px") << ": [" << rect.x << ", " << rect.y << ", " << rect.width << ", "
            << rect.height << "] leaves the " << pixels.cols << "x" << pixels.rows << " image " << resolved.string();
      return InvalidArgumentError(error.str());
    }
    pixels = pixels(rect).clone();
  }
  m.texture = std::make_shared<const MipTexture>(pixels);
  return m;
}

StatusOr<Material> ParseMaterial(const json& j, const std::string& path, const Context& context, Scene* scene) {
  if (!j.is_object()) return InvalidArgumentError(path + ": want an object, got " + std::string(j.type_name()));
  PX_ASSIGN_OR_RETURN(MaterialKind kind, ParseKind(j, path));
  if (kind == MaterialKind::kTexture) return ParseTexture(j, path, context, scene);
  return ParseProcedural(j, path, kind);
}

// "material": "name" or an inline material object. Returns the index in scene->materials.
StatusOr<int> ResolveMaterial(const json& object, const std::string& parent, const Context& context, Scene* scene) {
  PX_ASSIGN_OR_RETURN(const json* value, px::json::GetField(object, "material", parent));
  const std::string path = FieldPath(parent, "material");
  if (value->is_string()) {
    const int index = scene->FindMaterial(value->get<std::string>());
    if (index < 0) return InvalidArgumentError(path + ": no material named '" + value->get<std::string>() + "'");
    return index;
  }
  PX_ASSIGN_OR_RETURN(Material material, ParseMaterial(*value, path, context, scene));
  material.name = path;
  scene->materials.push_back(std::move(material));
  return static_cast<int>(scene->materials.size()) - 1;
}

Status ParsePlane(const json& j, const std::string& path, const Context& context, Scene* scene) {
  PX_RETURN_IF_ERROR(CheckKeys(
      j, path, {"type", "name", "centre_m", "normal", "up", "rotation_deg", "width_m", "height_m", "material"}));
  Plane plane;
  PX_ASSIGN_OR_RETURN(plane.name, px::json::GetStringOr(j, "name", path, path));
  PX_ASSIGN_OR_RETURN(plane.centre_m, GetVector3(j, "centre_m", path));
  Eigen::Vector3d normal(0, 0, -1), up(0, -1, 0);  // facing the camera, upright
  if (j.contains("normal")) {
    if (j.contains("rotation_deg")) {
      return InvalidArgumentError(FieldPath(path, "rotation_deg") + ": give either normal (and up) or rotation_deg");
    }
    PX_ASSIGN_OR_RETURN(normal, GetUnitVector3(j, "normal", path));
    if (j.contains("up")) {
      PX_ASSIGN_OR_RETURN(up, GetUnitVector3(j, "up", path));
    }
  } else {
    if (j.contains("up")) return InvalidArgumentError(FieldPath(path, "up") + ": only used with normal");
    PX_ASSIGN_OR_RETURN(Eigen::Matrix3d rotation, GetRotation(j, "rotation_deg", path));
    normal = rotation * normal;
    up = rotation * up;
  }
  const Eigen::Vector3d right = up.cross(normal);
  if (right.norm() < 1e-6) {
    return InvalidArgumentError(FieldPath(path, "up") + ": parallel to the normal, so the texture has no up");
  }
  plane.normal = normal;
  plane.right = right.normalized();
  plane.down = plane.right.cross(plane.normal);
  PX_ASSIGN_OR_RETURN(plane.width_m, GetPositive(j, "width_m", path));
  PX_ASSIGN_OR_RETURN(plane.height_m, GetPositive(j, "height_m", path));
  PX_ASSIGN_OR_RETURN(plane.material, ResolveMaterial(j, path, context, scene));
  scene->planes.push_back(std::move(plane));
  return OkStatus();
}

Status ParseBox(const json& j, const std::string& path, const Context& context, Scene* scene) {
  PX_RETURN_IF_ERROR(CheckKeys(j, path, {"type", "name", "centre_m", "size_m", "rotation_deg", "material"}));
  Box box;
  PX_ASSIGN_OR_RETURN(box.name, px::json::GetStringOr(j, "name", path, path));
  PX_ASSIGN_OR_RETURN(box.centre_m, GetVector3(j, "centre_m", path));
  PX_ASSIGN_OR_RETURN(Eigen::Vector3d size, GetVector3(j, "size_m", path));
  if (!(size.minCoeff() > 0)) return InvalidArgumentError(FieldPath(path, "size_m") + ": every side must be positive");
  box.half_size_m = 0.5 * size;
  PX_ASSIGN_OR_RETURN(box.world_from_box, GetRotation(j, "rotation_deg", path));
  PX_ASSIGN_OR_RETURN(box.material, ResolveMaterial(j, path, context, scene));
  scene->boxes.push_back(std::move(box));
  return OkStatus();
}

Status ParseSphere(const json& j, const std::string& path, const Context& context, Scene* scene) {
  PX_RETURN_IF_ERROR(CheckKeys(j, path, {"type", "name", "centre_m", "radius_m", "material"}));
  Sphere sphere;
  PX_ASSIGN_OR_RETURN(sphere.name, px::json::GetStringOr(j, "name", path, path));
  PX_ASSIGN_OR_RETURN(sphere.centre_m, GetVector3(j, "centre_m", path));
  PX_ASSIGN_OR_RETURN(sphere.radius_m, GetPositive(j, "radius_m", path));
  PX_ASSIGN_OR_RETURN(sphere.material, ResolveMaterial(j, path, context, scene));
  scene->spheres.push_back(std::move(sphere));
  return OkStatus();
}

Status ParseMaterials(const json& j, const Context& context, Scene* scene) {
  if (!j.contains("materials")) return OkStatus();
  const json& materials = j["materials"];
  if (!materials.is_object()) {
    return InvalidArgumentError("materials: want an object of named materials, got " +
                                std::string(materials.type_name()));
  }
  // Procedural materials first, so textures can name them as fallbacks.
  for (int pass = 0; pass < 2; ++pass) {
    for (const auto& [name, value] : materials.items()) {
      const std::string path = FieldPath("materials", name);
      const bool is_texture = value.is_object() && value.value("type", std::string()) == "texture";
      if (is_texture != (pass == 1)) continue;
      PX_ASSIGN_OR_RETURN(Material material, ParseMaterial(value, path, context, scene));
      material.name = name;
      scene->materials.push_back(std::move(material));
    }
  }
  return OkStatus();
}

Status ParseLight(const json& j, Scene* scene) {
  if (!j.contains("light")) return OkStatus();
  const json& light = j["light"];
  const std::string path = "light";
  if (!light.is_object()) return InvalidArgumentError("light: want an object");
  PX_RETURN_IF_ERROR(CheckKeys(light, path, {"towards_light", "ambient", "diffuse"}));
  if (light.contains("towards_light")) {
    PX_ASSIGN_OR_RETURN(scene->light.towards_light, GetUnitVector3(light, "towards_light", path));
  }
  PX_ASSIGN_OR_RETURN(scene->light.ambient, GetInRange(light, "ambient", path, scene->light.ambient, 0, 4));
  PX_ASSIGN_OR_RETURN(scene->light.diffuse, GetInRange(light, "diffuse", path, scene->light.diffuse, 0, 4));
  return OkStatus();
}

Status ParseDocument(const json& j, const Context& context, Scene* scene) {
  if (!j.is_object()) return InvalidArgumentError("document: want an object, got " + std::string(j.type_name()));
  PX_RETURN_IF_ERROR(CheckKeys(j, "", {"name", "background_rgb", "backdrop", "light", "materials", "objects"}));
  PX_ASSIGN_OR_RETURN(scene->name, px::json::GetStringOr(j, "name", "", scene->name));
  PX_ASSIGN_OR_RETURN(scene->background_bgr, GetRgbOr(j, "background_rgb", "", scene->background_bgr));
  PX_RETURN_IF_ERROR(ParseLight(j, scene));
  PX_RETURN_IF_ERROR(ParseMaterials(j, context, scene));
  if (j.contains("backdrop")) {
    const json& b = j["backdrop"];
    if (!b.is_object()) return InvalidArgumentError("backdrop: want an object, got " + std::string(b.type_name()));
    PX_RETURN_IF_ERROR(CheckKeys(b, "backdrop", {"distance_m", "material"}));
    Backdrop backdrop;
    PX_ASSIGN_OR_RETURN(backdrop.distance_m, GetPositive(b, "distance_m", "backdrop"));
    PX_ASSIGN_OR_RETURN(backdrop.material, ResolveMaterial(b, "backdrop", context, scene));
    scene->backdrop = backdrop;
  }
  PX_ASSIGN_OR_RETURN(const json* objects, px::json::GetField(j, "objects", ""));
  if (!objects->is_array()) {
    return InvalidArgumentError("objects: want an array, got " + std::string(objects->type_name()));
  }
  for (size_t i = 0; i < objects->size(); ++i) {
    const json& object = (*objects)[i];
    const std::string path = IndexPath("objects", i);
    if (!object.is_object())
      return InvalidArgumentError(path + ": want an object, got " + std::string(object.type_name()));
    PX_ASSIGN_OR_RETURN(std::string type, px::json::GetString(object, "type", path));
    if (type == "plane") {
      PX_RETURN_IF_ERROR(ParsePlane(object, path, context, scene));
    } else if (type == "box") {
      PX_RETURN_IF_ERROR(ParseBox(object, path, context, scene));
    } else if (type == "sphere") {
      PX_RETURN_IF_ERROR(ParseSphere(object, path, context, scene));
    } else {
      return InvalidArgumentError(FieldPath(path, "type") + ": '" + type + "' is not one of plane, box, sphere");
    }
  }
  if (objects->empty() && !scene->backdrop) return InvalidArgumentError("objects: empty and no backdrop");
  return OkStatus();
}

}  // namespace

StatusOr<Scene> ParseSceneJson(const json& j, const std::filesystem::path& base_dir, const std::string& what) {
  Scene scene;
  scene.name = std::filesystem::path(what).stem().string();  // unless the document names itself
  const Context context{base_dir, what};
  PX_RETURN_IF_ERROR(ParseDocument(j, context, &scene).WithContext(what));
  return scene;
}

StatusOr<Scene> ParseScene(const std::string& text, const std::filesystem::path& base_dir, const std::string& what) {
  PX_ASSIGN_OR_RETURN(json j, px::json::Parse(text, what));
  return ParseSceneJson(j, base_dir, what);
}

StatusOr<Scene> LoadScene(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return NotFoundError("scene file " + file.string() + " cannot be opened");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return DataLossError("scene file " + file.string() + ": read failed");
  PX_ASSIGN_OR_RETURN(Scene scene, ParseScene(text.str(), file.parent_path(), file.string()));
  scene.file = file;
  return scene;
}

}  // namespace px::sim
