#include "device/face_cascades.h"

#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

namespace px::device {

StatusOr<std::shared_ptr<const direct::FaceDetector>> LoadFaceDetector(const std::filesystem::path& dir) {
  const std::vector<std::pair<std::string, bool>> wanted = {{"haarcascade_frontalface_default", false},
                                                            {"haarcascade_frontalface_alt2", false},
                                                            {"haarcascade_profileface", true}};
  std::vector<direct::CascadeText> cascades;
  for (const auto& [name, profile] : wanted) {
    const std::filesystem::path file = dir / (name + ".xml");
    std::ifstream in(file);
    if (!in) return NotFoundError("face cascade " + file.string() + ": cannot open (Debian package opencv-data)");
    std::stringstream text;
    text << in.rdbuf();
    cascades.push_back({name, text.str(), profile});
  }
  PX_ASSIGN_OR_RETURN(std::unique_ptr<direct::FaceDetector> detector, direct::FaceDetector::Create(cascades));
  return std::shared_ptr<const direct::FaceDetector>(std::move(detector));
}

}  // namespace px::device
