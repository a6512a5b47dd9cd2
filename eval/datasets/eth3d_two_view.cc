#include "eval/datasets/eth3d_two_view.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>

#include "eval/datasets/pfm.h"

namespace px::eval {
namespace {

namespace fs = std::filesystem;

// key=value lines of calib.txt.
StatusOr<std::map<std::string, std::string>> ReadCalib(const fs::path& path) {
  std::ifstream in(path);
  if (!in) return NotFoundError(path.string() + ": cannot open");
  std::map<std::string, std::string> values;
  std::string line;
  while (std::getline(in, line)) {
    const size_t eq = line.find('=');
    if (eq == std::string::npos) continue;
    values[line.substr(0, eq)] = line.substr(eq + 1);
  }
  return values;
}

StatusOr<double> CalibNumber(const std::map<std::string, std::string>& calib,
                             const std::string& key,
                             const fs::path& file) {
  const auto it = calib.find(key);
  if (it == calib.end()) return DataLossError(file.string() + ": missing key " + key);
  char* end = nullptr;
  const double value = std::strtod(it->second.c_str(), &end);
  if (end == it->second.c_str() || !std::isfinite(value)) {
    return DataLossError(file.string() + ": " + key + " = '" + it->second + "' is not a number");
  }
  return value;
}

// cam0=[fx 0 cx; 0 fy cy; 0 0 1] -> fx, cx, cy.
Status ParseCameraMatrix(const std::map<std::string, std::string>& calib,
                         const std::string& key,
                         const fs::path& file,
                         double* fx,
                         double* cx,
                         double* cy) {
  const auto it = calib.find(key);
  if (it == calib.end()) return DataLossError(file.string() + ": missing key " + key);
  std::string text = it->second;
  std::replace_if(
      text.begin(), text.end(), [](char c) { return c == '[' || c == ']' || c == ';'; }, ' ');
  std::istringstream in(text);
  double m[9];
  for (double& value : m) {
    if (!(in >> value))
      return DataLossError(file.string() + ": " + key + " = '" + it->second + "' is not a 3x3 matrix");
  }
  *fx = m[0];
  *cx = m[2];
  *cy = m[5];
  if (!(*fx > 0)) return DataLossError(file.string() + ": " + key + " has focal length " + std::to_string(*fx));
  return OkStatus();
}

}  // namespace

bool IsEth3dPairDir(const fs::path& dir) {
  return fs::exists(dir / "im0.png") && fs::exists(dir / "im1.png") && fs::exists(dir / "disp0.pfm") &&
         fs::exists(dir / "calib.txt");
}

StatusOr<StereoPair> LoadEth3dPair(const fs::path& dir) {
  const fs::path calib_path = dir / "calib.txt";
  PX_ASSIGN_OR_RETURN(const auto calib, ReadCalib(calib_path));
  double fx0 = 0, cx0 = 0, cy0 = 0, fx1 = 0, cx1 = 0, cy1 = 0;
  PX_RETURN_IF_ERROR(ParseCameraMatrix(calib, "cam0", calib_path, &fx0, &cx0, &cy0));
  PX_RETURN_IF_ERROR(ParseCameraMatrix(calib, "cam1", calib_path, &fx1, &cx1, &cy1));
  PX_ASSIGN_OR_RETURN(const double doffs, CalibNumber(calib, "doffs", calib_path));
  PX_ASSIGN_OR_RETURN(const double baseline_mm, CalibNumber(calib, "baseline", calib_path));
  PX_ASSIGN_OR_RETURN(const double ndisp, CalibNumber(calib, "ndisp", calib_path));
  if (doffs != 0 || fx0 != fx1 || cy0 != cy1) {
    return InvalidArgumentError(calib_path.string() + ": cameras differ (doffs " + std::to_string(doffs) +
                                "): not a plain rectified pair");
  }
  if (!(baseline_mm > 0)) return DataLossError(calib_path.string() + ": baseline = " + std::to_string(baseline_mm));

  const fs::path left_path = dir / "im0.png", right_path = dir / "im1.png";
  const cv::Mat left = cv::imread(left_path.string(), cv::IMREAD_COLOR);
  const cv::Mat right = cv::imread(right_path.string(), cv::IMREAD_COLOR);
  if (left.empty()) return DataLossError(left_path.string() + ": unreadable image");
  if (right.empty()) return DataLossError(right_path.string() + ": unreadable image");
  if (right.size() != left.size()) return DataLossError(right_path.string() + ": size differs from im0.png");
  PX_ASSIGN_OR_RETURN(cv::Mat gt, ReadPfm(dir / "disp0.pfm"));
  if (gt.type() != CV_32F || gt.size() != left.size()) {
    return DataLossError((dir / "disp0.pfm").string() + ": not a single-channel map of im0.png's size");
  }
  for (float& d : cv::Mat_<float>(gt)) {
    if (!std::isfinite(d) || d <= 0) d = std::numeric_limits<float>::quiet_NaN();
  }
  StereoPair pair =
      MakeRectifiedPair("eth3d/" + dir.filename().string(), left, right, fx0, cx0, cy0, baseline_mm / 1000.0);
  pair.gt_disparity = gt;
  pair.min_disparity = 0.5;
  pair.max_disparity = std::min(ndisp, 64.0);
  return pair;
}

}  // namespace px::eval
