#include "pipeline/direct/framing.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace px::direct {

double MaxFocalKeepingInside(const std::vector<Subject>& subjects,
                             const CameraModel& camera,
                             const Rigid3& cam_from_world,
                             double margin_px) {
  double best = std::numeric_limits<double>::infinity();
  const double aspect = camera.fx > 0 ? camera.fy / camera.fx : 1.0;
  // Room from the principal point to each edge, less the margin.
  const double left = camera.cx - margin_px, right = camera.width - 1 - margin_px - camera.cx;
  const double top = camera.cy - margin_px, bottom = camera.height - 1 - margin_px - camera.cy;
  for (const Subject& subject : subjects) {
    for (const Eigen::Vector3d& corner : subject.corners_in_world) {
      const Eigen::Vector3d p = cam_from_world * corner;
      if (!(p.z() > 1e-6)) return 0.0;
      const double x = p.x() / p.z(), y = aspect * p.y() / p.z();
      if (x > 0) best = std::min(best, right / x);
      if (x < 0) best = std::min(best, left / -x);
      if (y > 0) best = std::min(best, bottom / y);
      if (y < 0) best = std::min(best, top / -y);
    }
  }
  return std::max(0.0, best);
}

bool SubjectsInside(const std::vector<Subject>& subjects,
                    const CameraModel& camera,
                    const Rigid3& cam_from_world,
                    double margin_px) {
  for (const Subject& subject : subjects) {
    for (const Eigen::Vector3d& corner : subject.corners_in_world) {
      Eigen::Vector2d pixel;
      if (!camera.Project(cam_from_world * corner, &pixel)) return false;
      if (pixel.x() < margin_px || pixel.y() < margin_px || pixel.x() > camera.width - 1 - margin_px ||
          pixel.y() > camera.height - 1 - margin_px) {
        return false;
      }
    }
  }
  return true;
}

double ProjectedHeightPx(const Subject& subject, const CameraModel& camera, const Rigid3& cam_from_world) {
  const Eigen::Vector3d top = 0.5 * (subject.corners_in_world[0] + subject.corners_in_world[1]);
  const Eigen::Vector3d bottom = 0.5 * (subject.corners_in_world[2] + subject.corners_in_world[3]);
  Eigen::Vector2d a, b;
  if (!camera.Project(cam_from_world * top, &a) || !camera.Project(cam_from_world * bottom, &b)) return 0.0;
  return (a - b).norm();
}

double SubjectDepthIn(const Subject& subject, const Rigid3& cam_from_world) {
  return (cam_from_world * subject.CentreInWorld()).z();
}

}  // namespace px::direct
