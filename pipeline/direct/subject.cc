#include "pipeline/direct/subject.h"

namespace px {

Eigen::Vector3d Subject::CentreInWorld() const {
  return 0.25 * (corners_in_world[0] + corners_in_world[1] + corners_in_world[2] + corners_in_world[3]);
}

Eigen::Vector3d Subject::LowerHalfCentreInWorld() const {
  const Eigen::Vector3d top = 0.5 * (corners_in_world[0] + corners_in_world[1]);
  const Eigen::Vector3d bottom = 0.5 * (corners_in_world[2] + corners_in_world[3]);
  return top + 0.75 * (bottom - top);
}

double Subject::WidthM() const { return (corners_in_world[1] - corners_in_world[0]).norm(); }

double Subject::HeightM() const { return (corners_in_world[3] - corners_in_world[0]).norm(); }

}  // namespace px
