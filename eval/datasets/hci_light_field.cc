#include "eval/datasets/hci_light_field.h"

#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>

#include "eval/datasets/pfm.h"

namespace px::eval {
namespace {

namespace fs = std::filesystem;

// key = value lines of an INI file, section names dropped (keys are unique in parameters.cfg).
StatusOr<std::map<std::string, std::string>> ReadCfg(const fs::path& path) {
  std::ifstream in(path);
  if (!in) return NotFoundError(path.string() + ": cannot open");
  std::map<std::string, std::string> values;
  std::string line;
  auto trim = [](std::string s) {
    const size_t begin = s.find_first_not_of(" \t\r");
    const size_t end = s.find_last_not_of(" \t\r");
    return begin == std::string::npos ? std::string() : s.substr(begin, end - begin + 1);
  };
  while (std::getline(in, line)) {
    const size_t eq = line.find('=');
    if (eq == std::string::npos || line.starts_with('[') || line.starts_with('#')) continue;
    values[trim(line.substr(0, eq))] = trim(line.substr(eq + 1));
  }
  return values;
}

StatusOr<double> Number(const std::map<std::string, std::string>& cfg, const std::string& key, const fs::path& file) {
  auto it = cfg.find(key);
  if (it == cfg.end()) return DataLossError(file.string() + ": missing key " + key);
  try {
    return std::stod(it->second);
  } catch (const std::exception&) {
    return DataLossError(file.string() + ": " + key + " = '" + it->second + "' is not a number");
  }
}

}  // namespace

cv::Mat HciLightField::GtDepth() const {
  cv::Mat depth(gt_disparity.size(), CV_32F);
  for (int y = 0; y < depth.rows; ++y) {
    for (int x = 0; x < depth.cols; ++x) {
      depth.at<float>(y, x) = static_cast<float>(DepthFromDisparity(gt_disparity.at<float>(y, x)));
    }
  }
  return depth;
}

CameraModel HciLightField::MetadataCamera(int index, int width, int height) const {
  CameraModel camera = CameraModel::Pinhole(width, height, focal_px);
  camera.cx += offset_px * (index % cols - cols / 2);
  camera.cy += offset_px * (index / cols - rows / 2);
  return camera;
}

std::vector<View> HciLightField::CentreGrid(int radius) const {
  std::vector<View> grid;
  for (int r = rows / 2 - radius; r <= rows / 2 + radius; ++r) {
    for (int c = cols / 2 - radius; c <= cols / 2 + radius; ++c) grid.push_back(views[r * cols + c]);
  }
  return grid;
}

StatusOr<HciLightField> LoadHciLightField(const fs::path& dir) {
  const fs::path cfg_path = dir / "parameters.cfg";
  PX_ASSIGN_OR_RETURN(auto cfg, ReadCfg(cfg_path));
  HciLightField lf;
  lf.scene = cfg.contains("scene") ? cfg.at("scene") : dir.filename().string();
  PX_ASSIGN_OR_RETURN(const double focal_mm, Number(cfg, "focal_length_mm", cfg_path));
  PX_ASSIGN_OR_RETURN(const double sensor_mm, Number(cfg, "sensor_size_mm", cfg_path));
  PX_ASSIGN_OR_RETURN(const double width, Number(cfg, "image_resolution_x_px", cfg_path));
  PX_ASSIGN_OR_RETURN(const double height, Number(cfg, "image_resolution_y_px", cfg_path));
  PX_ASSIGN_OR_RETURN(const double cams_x, Number(cfg, "num_cams_x", cfg_path));
  PX_ASSIGN_OR_RETURN(const double cams_y, Number(cfg, "num_cams_y", cfg_path));
  PX_ASSIGN_OR_RETURN(const double baseline_mm, Number(cfg, "baseline_mm", cfg_path));
  PX_ASSIGN_OR_RETURN(lf.focus_distance_m, Number(cfg, "focus_distance_m", cfg_path));
  PX_ASSIGN_OR_RETURN(lf.disp_min, Number(cfg, "disp_min", cfg_path));
  PX_ASSIGN_OR_RETURN(lf.disp_max, Number(cfg, "disp_max", cfg_path));
  if (focal_mm <= 0 || sensor_mm <= 0 || width <= 0 || height <= 0 || cams_x < 1 || cams_y < 1 || baseline_mm <= 0 ||
      lf.focus_distance_m <= 0) {
    return DataLossError(cfg_path.string() + ": non-positive camera parameter");
  }
  lf.rows = static_cast<int>(cams_y);
  lf.cols = static_cast<int>(cams_x);
  lf.focal_px = focal_mm / sensor_mm * width;
  lf.baseline_m = baseline_mm / 1000.0;
  lf.offset_px = lf.focal_px * lf.baseline_m / lf.focus_distance_m;

  for (int r = 0; r < lf.rows; ++r) {
    for (int c = 0; c < lf.cols; ++c) {
      const int index = r * lf.cols + c;
      char name[32];
      std::snprintf(name, sizeof(name), "input_Cam%03d.png", index);
      const fs::path image_path = dir / name;
      cv::Mat image = cv::imread(image_path.string(), cv::IMREAD_COLOR);
      if (image.empty()) return NotFoundError(image_path.string() + ": missing or unreadable");
      if (image.cols != static_cast<int>(width) || image.rows != static_cast<int>(height)) {
        return DataLossError(image_path.string() + ": " + std::to_string(image.cols) + "x" +
                             std::to_string(image.rows) + ", parameters.cfg says " + std::to_string(int(width)) + "x" +
                             std::to_string(int(height)));
      }
      View view;
      view.id = ViewId{index};
      view.image = image;
      const int dc = c - lf.cols / 2;
      const int dr = r - lf.rows / 2;
      view.camera = lf.MetadataCamera(index, image.cols, image.rows);
      const Eigen::Vector3d centre(dc * lf.baseline_m, dr * lf.baseline_m, 0);
      view.cam_from_world = Rigid3(Eigen::Quaterniond::Identity(), -centre);
      lf.views.push_back(std::move(view));
    }
  }
  const fs::path gt_path = dir / "gt_disp_lowres.pfm";
  if (fs::exists(gt_path)) {
    PX_ASSIGN_OR_RETURN(lf.gt_disparity, ReadPfm(gt_path));
    if (lf.gt_disparity.type() != CV_32F || lf.gt_disparity.size() != lf.views.front().image.size()) {
      return DataLossError(gt_path.string() + ": not a single-channel map of the views' size");
    }
  }
  return lf;
}

}  // namespace px::eval
