#include "sim/synthetic/scene_json.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <spdlog/sinks/ringbuffer_sink.h>
#include <stdlib.h>

#include <opencv2/imgcodecs.hpp>

#include "pipeline/core/log.h"
#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/sim_test_util.h"

namespace px::sim {
namespace {

using ::testing::HasSubstr;
using testing::TempDir;
using testing::WriteText;

// Sets an environment variable for the scope of a test.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    const char* old = std::getenv(name);
    if (old != nullptr) old_ = old;
    setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_)
      setenv(name_, old_->c_str(), 1);
    else
      unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

void WritePng(const std::filesystem::path& file, int width, int height) {
  cv::Mat image(height, width, CV_8UC3, cv::Scalar(10, 200, 30));
  ASSERT_TRUE(cv::imwrite(file.string(), image));
}

StatusOr<Scene> LoadText(const TempDir& dir, const std::string& text) {
  const std::filesystem::path file = dir.path() / "scene.json";
  WriteText(file, text);
  return LoadScene(file);
}

TEST(SceneJsonTest, ParsesObjectsAndMaterials) {
  TempDir dir;
  auto scene = LoadText(dir, R"({
    "name": "demo",
    "background_rgb": [10, 20, 30],
    "materials": {"grey": {"type": "flat", "rgb": [100, 110, 120]},
                  "c": {"type": "checker", "rgb_a": [0, 0, 0], "rgb_b": [255, 255, 255], "square_m": 0.1}},
    "objects": [
      {"type": "plane", "name": "floor", "centre_m": [0, 1, 2], "normal": [0, -1, 0], "up": [0, 0, 1],
       "width_m": 4, "height_m": 3, "material": "grey"},
      {"type": "plane", "centre_m": [0, 0, 3], "rotation_deg": [0, 90, 0], "width_m": 1, "height_m": 1,
       "material": "c"},
      {"type": "box", "centre_m": [0, 0, 2], "size_m": [1, 2, 3], "material": {"type": "flat", "rgb": [1, 2, 3]}},
      {"type": "sphere", "centre_m": [1, 0, 2], "radius_m": 0.25, "material": "grey"}]})");
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  EXPECT_EQ(scene->name, "demo");
  EXPECT_EQ(scene->background_bgr, cv::Vec3f(30, 20, 10));  // JSON is RGB, images BGR
  ASSERT_EQ(scene->planes.size(), 2u);
  ASSERT_EQ(scene->boxes.size(), 1u);
  ASSERT_EQ(scene->spheres.size(), 1u);
  EXPECT_EQ(scene->materials.size(), 3u);  // two named, one inline
  EXPECT_EQ(scene->materials[scene->planes[0].material].bgr_a, cv::Vec3f(120, 110, 100));
  // A floor facing up (-y) with "up" pointing away (+z): texture right is +x, down is -z.
  const Plane& floor = scene->planes[0];
  EXPECT_TRUE(floor.right.isApprox(Eigen::Vector3d(1, 0, 0)));
  EXPECT_TRUE(floor.down.isApprox(Eigen::Vector3d(0, 0, -1)));
  // rotation_deg turns the default card (facing the camera, -z) about y by 90 degrees.
  EXPECT_TRUE(scene->planes[1].normal.isApprox(Eigen::Vector3d(-1, 0, 0)));
  EXPECT_TRUE(scene->boxes[0].half_size_m.isApprox(Eigen::Vector3d(0.5, 1, 1.5)));
  EXPECT_TRUE(scene->warnings.empty());
}

TEST(SceneJsonTest, ErrorsNameTheFileAndTheField) {
  TempDir dir;
  struct Case {
    std::string text;
    std::string path;  // expected in the message
  };
  const std::vector<Case> cases = {
      {R"({"objects": [{"type": "sphere", "centre_m": [0, 0, 1], "radius_m": 1, "material": {"type": "flat", "rgb": [1, 2, 3]}},
                       {"type": "sphere", "centre_m": [0, 0, 1], "radius_m": "big", "material": "x"}]})",
       "objects[1].radius_m: want a number, got string"},
      {R"({"objects": [{"type": "plane", "centre_m": [0, 0], "width_m": 1, "height_m": 1, "material": "x"}]})",
       "objects[0].centre_m: want 3 numbers, got 2"},
      {R"({"materials": {"wall": {"type": "noise", "rgb_a": [1, 2, 3], "rgb_b": [1, 2, 300], "scale_m": 1}},
          "objects": []})",
       "materials.wall.rgb_b[2]: 300 is not in [0, 255]"},
      {R"({"materials": {"wall": {"type": "noise", "rgb_a": [1, 2, 3], "rgb_b": [1, 2, 3], "scale": 1}}, "objects": []})",
       "materials.wall.scale: unknown field"},
      {R"({"objects": [{"type": "box", "centre_m": [0, 0, 1], "size_m": [1, 1, 1], "material": "missing"}]})",
       "objects[0].material: no material named 'missing'"},
      {R"({"objects": [{"type": "cone"}]})", "objects[0].type: 'cone' is not one of plane, box, sphere"},
      {R"({"materials": {"m": {"type": "plastic"}}, "objects": []})", "materials.m.type: 'plastic' is not one of"},
      {R"({"objects": [{"type": "plane", "centre_m": [0, 0, 1], "normal": [0, 0, -1], "up": [0, 0, 1],
          "width_m": 1, "height_m": 1, "material": {"type": "flat", "rgb": [1, 1, 1]}}]})",
       "objects[0].up: parallel to the normal"},
      {R"({"objects": [{"type": "sphere", "centre_m": [0, 0, 1], "radius_m": -1, "material": "x"}]})",
       "objects[0].radius_m: -1 is not positive"},
      {R"({"materials": {}})", "objects: missing"},
  };
  for (const Case& c : cases) {
    auto scene = LoadText(dir, c.text);
    ASSERT_FALSE(scene.ok()) << c.path;
    EXPECT_EQ(scene.status().code(), StatusCode::kInvalidArgument) << scene.status().ToString();
    EXPECT_THAT(scene.status().message(), HasSubstr((dir.path() / "scene.json").string())) << c.path;
    EXPECT_THAT(scene.status().message(), HasSubstr(c.path));
  }
}

TEST(SceneJsonTest, MalformedJsonNamesTheFileAndOffset) {
  TempDir dir;
  auto scene = LoadText(dir, R"({"objects": [}")");
  ASSERT_FALSE(scene.ok());
  EXPECT_THAT(scene.status().message(), HasSubstr("scene.json"));
  EXPECT_THAT(scene.status().message(), HasSubstr("byte"));
}

TEST(SceneJsonTest, MissingSceneFileIsNotFound) {
  auto scene = LoadScene("/nonexistent/dir/scene.json");
  EXPECT_EQ(scene.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(scene.status().message(), HasSubstr("/nonexistent/dir/scene.json"));
}

constexpr char kPhotoScene[] = R"({
  "materials": {"photo": {"type": "texture", "file": "%FILE%" %FALLBACK%}},
  "objects": [{"type": "plane", "centre_m": [0, 0, 1], "normal": [0, 0, -1], "width_m": 1, "height_m": 1,
               "material": "photo"}]})";

std::string PhotoScene(const std::string& file, const std::string& fallback) {
  std::string text = kPhotoScene;
  text.replace(text.find("%FILE%"), 6, file);
  text.replace(text.find("%FALLBACK%"), 10, fallback);
  return text;
}

TEST(SceneJsonTest, MissingTextureWithoutFallbackIsNotFound) {
  TempDir dir;
  auto scene = LoadText(dir, PhotoScene("nowhere/face.jpg", ""));
  ASSERT_FALSE(scene.ok());
  EXPECT_EQ(scene.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(scene.status().message(), HasSubstr((dir.path() / "nowhere/face.jpg").string()));
  EXPECT_THAT(scene.status().message(), HasSubstr("materials.photo.file"));
}

TEST(SceneJsonTest, MissingTextureWithFallbackWarnsAndUsesIt) {
  TempDir dir;
  auto sink = std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(16);
  Logger("sim")->sinks().push_back(sink);
  const std::string inline_fallback =
      R"(, "fallback": {"type": "noise", "rgb_a": [200, 150, 120], "rgb_b": [90, 60, 50], "scale_m": 0.1})";
  auto scene = LoadText(dir, PhotoScene("nowhere/face.jpg", inline_fallback));
  Logger("sim")->sinks().pop_back();
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  const Material& material = scene->materials[scene->planes[0].material];
  EXPECT_EQ(material.kind, MaterialKind::kNoise);
  EXPECT_EQ(material.name, "photo");
  ASSERT_EQ(scene->warnings.size(), 1u);
  EXPECT_THAT(scene->warnings[0], HasSubstr("nowhere/face.jpg"));
  bool logged = false;
  for (const std::string& line : sink->last_formatted())
    logged = logged || line.find("nowhere/face.jpg") != std::string::npos;
  EXPECT_TRUE(logged) << "no warning naming the missing file was logged";

  // A fallback may also name a procedural material.
  auto named = LoadText(dir, R"({"materials": {
      "skin": {"type": "flat", "rgb": [220, 180, 150]},
      "photo": {"type": "texture", "file": "gone.png", "fallback": "skin"}},
    "objects": [{"type": "sphere", "centre_m": [0, 0, 1], "radius_m": 0.2, "material": "photo"}]})");
  ASSERT_TRUE(named.ok()) << named.status().ToString();
  EXPECT_EQ(named->materials[named->spheres[0].material].kind, MaterialKind::kFlat);
}

TEST(SceneJsonTest, TexturePathsResolveAgainstSceneFolderOrDataDir) {
  TempDir dir, data;
  std::filesystem::create_directories(dir.path() / "textures");
  std::filesystem::create_directories(data.path() / "set");
  WritePng(dir.path() / "textures" / "local.png", 40, 30);
  WritePng(data.path() / "set" / "shared.png", 64, 48);
  ScopedEnv env("PX_DATA_DIR", data.path().string());
  EXPECT_EQ(SharedDataDir(), data.path());

  auto local = LoadText(dir, PhotoScene("textures/local.png", ""));
  ASSERT_TRUE(local.ok()) << local.status().ToString();
  EXPECT_EQ(local->materials[0].texture->width(), 40);

  auto shared = LoadText(dir, PhotoScene("data:set/shared.png", ", \"crop_px\": [4, 8, 20, 10]"));
  ASSERT_TRUE(shared.ok()) << shared.status().ToString();
  ASSERT_NE(shared->materials[0].texture, nullptr);
  EXPECT_EQ(shared->materials[0].texture->width(), 20);
  EXPECT_EQ(shared->materials[0].texture->height(), 10);

  auto outside = LoadText(dir, PhotoScene("data:set/shared.png", ", \"crop_px\": [50, 8, 20, 10]"));
  ASSERT_FALSE(outside.ok());
  EXPECT_THAT(outside.status().message(), HasSubstr("materials.photo.crop_px"));
  EXPECT_THAT(outside.status().message(), HasSubstr("64x48"));
}

TEST(SceneJsonTest, UndecodableTextureIsDataLoss) {
  TempDir dir;
  WriteText(dir.path() / "broken.png", "not a png");
  auto scene = LoadText(dir, PhotoScene("broken.png", ""));
  ASSERT_FALSE(scene.ok());
  EXPECT_EQ(scene.status().code(), StatusCode::kDataLoss);
  EXPECT_THAT(scene.status().message(), HasSubstr("broken.png"));
}

TEST(DataPathsTest, DefaultsAndOverrides) {
  {
    ScopedEnv env("PX_SCENES_DIR", "/somewhere/scenes");
    EXPECT_EQ(ScenesDir(), std::filesystem::path("/somewhere/scenes"));
  }
  ScopedEnv clear_data("PX_DATA_DIR", "");
  ScopedEnv clear_scenes("PX_SCENES_DIR", "");
  // Without them, a program in the build tree finds the folders beside its source tree.
  EXPECT_EQ(ScenesDir(), (std::filesystem::path(PX_SOURCE_DIR) / "sim" / "scenes").lexically_normal());
  EXPECT_EQ(SharedDataDir(), (std::filesystem::path(PX_SOURCE_DIR) / ".." / "shared" / "data").lexically_normal());
  EXPECT_TRUE(std::filesystem::exists(ScenesDir() / "still_life.json"));
}

}  // namespace
}  // namespace px::sim
