#include "eval/datasets/middlebury_mview.h"

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

namespace px::eval {

StatusOr<std::vector<View>> LoadMiddleburyMview(const std::filesystem::path& dir) {
  std::filesystem::path par;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() > 8 && name.substr(name.size() - 8) == "_par.txt") par = entry.path();
  }
  if (ec) return NotFoundError(dir.string() + ": " + ec.message());
  if (par.empty()) return NotFoundError(dir.string() + ": no *_par.txt camera file");
  std::ifstream in(par);
  int count = 0;
  if (!(in >> count) || count < 1 || count > 10000) {
    return InvalidArgumentError(par.string() + ": first line is not an image count");
  }
  std::vector<View> views;
  for (int i = 0; i < count; ++i) {
    std::string file;
    double k[9], r[9], t[3];
    in >> file;
    for (double& v : k) in >> v;
    for (double& v : r) in >> v;
    for (double& v : t) in >> v;
    if (!in) return InvalidArgumentError(par.string() + ": camera " + std::to_string(i + 1) + " is incomplete");
    View view;
    view.id.value = i;
    view.image = cv::imread((dir / file).string(), cv::IMREAD_COLOR);
    if (view.image.empty()) return NotFoundError((dir / file).string() + ": cannot read image");
    if (k[1] != 0 || k[3] != 0 || k[6] != 0 || k[7] != 0 || k[8] != 1) {
      return InvalidArgumentError(par.string() + ": camera " + file + " has a skewed or unnormalised K");
    }
    view.camera = CameraModel::Pinhole(view.image.cols, view.image.rows, k[0]);
    view.camera.fy = k[4];
    view.camera.cx = k[2];
    view.camera.cy = k[5];
    Eigen::Matrix3d rotation;
    rotation << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
    view.cam_from_world = Rigid3(Eigen::Quaterniond(rotation).normalized(), Eigen::Vector3d(t[0], t[1], t[2]));
    views.push_back(std::move(view));
  }
  return views;
}

}  // namespace px::eval
