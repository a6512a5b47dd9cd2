#include "eval/datasets/llff.h"

#include <algorithm>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "eval/datasets/npy.h"

namespace px::eval {
namespace {

namespace fs = std::filesystem;

struct ColmapCamera {
  int model = -1;
  uint64_t width = 0;
  uint64_t height = 0;
  std::vector<double> params;
};

// The first camera of a COLMAP cameras.bin (LLFF scenes share one camera).
StatusOr<ColmapCamera> ReadFirstColmapCamera(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return NotFoundError(path.string() + ": cannot open");
  uint64_t count = 0;
  in.read(reinterpret_cast<char*>(&count), sizeof(count));
  if (!in || count == 0) return DataLossError(path.string() + ": no cameras");
  int32_t id = 0;
  ColmapCamera camera;
  int32_t model = 0;
  in.read(reinterpret_cast<char*>(&id), sizeof(id));
  in.read(reinterpret_cast<char*>(&model), sizeof(model));
  in.read(reinterpret_cast<char*>(&camera.width), sizeof(camera.width));
  in.read(reinterpret_cast<char*>(&camera.height), sizeof(camera.height));
  camera.model = model;
  // COLMAP model ids: 0 SIMPLE_PINHOLE (f cx cy), 1 PINHOLE (fx fy cx cy), 2 SIMPLE_RADIAL (f cx cy k).
  const int num_params = model == 0 ? 3 : model == 1 ? 4 : model == 2 ? 4 : -1;
  if (num_params < 0)
    return InvalidArgumentError(path.string() + ": camera model " + std::to_string(model) + " is not supported");
  camera.params.resize(num_params);
  in.read(reinterpret_cast<char*>(camera.params.data()), num_params * sizeof(double));
  if (!in) return DataLossError(path.string() + ": truncated");
  return camera;
}

}  // namespace

StatusOr<LlffScene> LoadLlffScene(const fs::path& dir, const std::string& images) {
  const fs::path poses_path = dir / "poses_bounds.npy";
  PX_ASSIGN_OR_RETURN(NpyArray poses, ReadNpyFloat64(poses_path));
  if (poses.shape.size() != 2 || poses.shape[1] != 17) {
    return DataLossError(poses_path.string() + ": shape is not (N, 17)");
  }
  const size_t n = poses.shape[0];
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir / images)) {
    if (entry.path().extension() == ".png" || entry.path().extension() == ".jpg") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  if (files.size() != n) {
    return DataLossError((dir / images).string() + ": " + std::to_string(files.size()) +
                         " images, poses_bounds.npy has " + std::to_string(n) + " rows");
  }
  std::optional<ColmapCamera> colmap;
  if (fs::exists(dir / "sparse/0/cameras.bin")) {
    PX_ASSIGN_OR_RETURN(ColmapCamera camera, ReadFirstColmapCamera(dir / "sparse/0/cameras.bin"));
    colmap = camera;
  }

  LlffScene scene;
  for (size_t i = 0; i < n; ++i) {
    const double* row = &poses.values[i * 17];
    auto m = [&](int r, int c) { return row[r * 5 + c]; };
    cv::Mat image = cv::imread(files[i].string(), cv::IMREAD_COLOR);
    if (image.empty()) return NotFoundError(files[i].string() + ": unreadable");
    const double full_height = m(0, 4), full_width = m(1, 4), full_focal = m(2, 4);
    if (full_width <= 0 || full_height <= 0 || full_focal <= 0) {
      return DataLossError(poses_path.string() + ": row " + std::to_string(i) + " has no (H, W, f)");
    }
    scene.downscale = full_width / image.cols;
    // LLFF columns are (down, right, backwards); OpenCV's camera axes are (right, down, forward).
    Eigen::Matrix3d world_from_cam;
    for (int r = 0; r < 3; ++r) {
      world_from_cam(r, 0) = m(r, 1);
      world_from_cam(r, 1) = m(r, 0);
      world_from_cam(r, 2) = -m(r, 2);
    }
    const Eigen::Vector3d centre(m(0, 3), m(1, 3), m(2, 3));
    View view;
    view.id = ViewId{static_cast<int32_t>(i)};
    view.image = image;
    view.cam_from_world = Rigid3::FromMatrix(world_from_cam.transpose(), -(world_from_cam.transpose() * centre));
    view.camera = CameraModel::Pinhole(image.cols, image.rows, full_focal / scene.downscale);
    if (colmap && colmap->width == static_cast<uint64_t>(full_width + 0.5)) {
      // COLMAP puts pixel centres at +0.5; OpenCV at integers.
      view.camera.cx = (colmap->params[colmap->model == 1 ? 2 : 1]) / scene.downscale - 0.5;
      view.camera.cy = (colmap->params[colmap->model == 1 ? 3 : 2]) / scene.downscale - 0.5;
      if (colmap->model == 2) view.camera.distortion[0] = colmap->params[3];
    }
    scene.views.push_back(std::move(view));
    scene.near_depth.push_back(row[15]);
    scene.far_depth.push_back(row[16]);
  }
  return scene;
}

}  // namespace px::eval
