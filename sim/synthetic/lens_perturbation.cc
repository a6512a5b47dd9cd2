#include "sim/synthetic/lens_perturbation.h"

#include <Eigen/Geometry>
#include <cmath>
#include <opencv2/core.hpp>
#include <sstream>
#include <string>

namespace px {
namespace {

Status OutOfRange(const std::string& field, double value, const std::string& range) {
  std::ostringstream text;
  text << "lens perturbation: " << field << " = " << value << " is outside " << range;
  return InvalidArgumentError(text.str());
}

}  // namespace

Status LensPerturbation::Validate() const {
  if (!(focal_relative >= 0 && focal_relative <= 0.2)) return OutOfRange("focal_relative", focal_relative, "[0, 0.2]");
  if (!(principal_point_px >= 0 && principal_point_px <= 50)) {
    return OutOfRange("principal_point_px", principal_point_px, "[0, 50]");
  }
  if (!(rotation_deg >= 0 && rotation_deg <= 10)) return OutOfRange("rotation_deg", rotation_deg, "[0, 10]");
  if (!(centre_m >= 0 && centre_m <= 0.05)) return OutOfRange("centre_m", centre_m, "[0, 0.05]");
  return OkStatus();
}

RigCalibration PerturbLenses(const RigCalibration& factory, const LensPerturbation& magnitudes, uint64_t seed) {
  RigCalibration truth = factory;
  // cv::RNG takes a 64-bit state; mix the seed so that 1, 2, 3 give unrelated draws.
  cv::RNG rng(seed * 0x9e3779b97f4a7c15ULL + 0x632be59bd9b4e019ULL);
  const auto draw = [&rng](double magnitude) { return rng.uniform(-1.0, 1.0) * magnitude; };
  for (LensCalibration& lens : truth.lenses) {
    const double scale = 1.0 + draw(magnitudes.focal_relative);
    lens.camera.fx *= scale;
    lens.camera.fy *= scale;
    lens.camera.cx += draw(magnitudes.principal_point_px);
    lens.camera.cy += draw(magnitudes.principal_point_px);
    const double k = M_PI / 180.0;
    const double rx = draw(magnitudes.rotation_deg), ry = draw(magnitudes.rotation_deg),
                 rz = draw(magnitudes.rotation_deg);
    // The lens turns about its own axes: cam_from_rig' = turn * cam_from_rig, centre moved.
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(rx * k, Eigen::Vector3d::UnitX()) *
                                  Eigen::AngleAxisd(ry * k, Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(rz * k, Eigen::Vector3d::UnitZ()));
    const Eigen::Vector3d centre =
        CameraCentre(lens.cam_from_rig) +
        Eigen::Vector3d(draw(magnitudes.centre_m), draw(magnitudes.centre_m), draw(magnitudes.centre_m));
    const Eigen::Quaterniond rotation = (turn * lens.cam_from_rig.rotation).normalized();
    lens.cam_from_rig = Rigid3(rotation, -(rotation * centre));
  }
  return truth;
}

}  // namespace px
