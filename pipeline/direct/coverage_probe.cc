#include "pipeline/direct/coverage_probe.h"

#include <chrono>
#include <cmath>
#include <string>

#include "pipeline/core/stage_clock.h"

namespace px::direct {

double ThinHoleBias(double scale) { return std::pow(2.0 / (1.0 + scale), 3); }

namespace {

bool SameCamera(const CameraModel& a, const CameraModel& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy && a.cx == b.cx && a.cy == b.cy &&
         a.distortion == b.distortion;
}

}  // namespace

std::optional<double> CoverageProbe::Recall(const CameraModel& output_camera, const Rigid3& cam_from_world) const {
  const std::lock_guard<std::mutex> lock(mutex_);
  for (const Remembered& r : remembered_) {
    if (SameCamera(r.camera, output_camera) && r.cam_from_world.rotation.coeffs() == cam_from_world.rotation.coeffs() &&
        r.cam_from_world.translation == cam_from_world.translation) {
      return r.score;
    }
  }
  return std::nullopt;
}

StatusOr<double> CoverageProbe::HoleScore(const CameraModel& output_camera, const Rigid3& cam_from_world) {
  if (coverage_ == nullptr || !*coverage_) return FailedPreconditionError("direction: no coverage function");
  if (const std::optional<double> known = Recall(output_camera, cam_from_world)) return *known;
  const auto start = std::chrono::steady_clock::now();
  const CameraModel camera = scale_ < 1.0 ? output_camera.Scaled(scale_) : output_camera;
  StatusOr<CoverageReport> report = (*coverage_)(camera, cam_from_world);
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    ++calls_;
    ms_ += MsSince(start);
  }
  if (!report.ok()) return report.status().WithContext("coverage");
  if (report->width <= 0) {
    return InternalError("coverage: report without a size (width " + std::to_string(report->width) + ")");
  }
  const double measured_scale = static_cast<double>(report->width) / output_camera.width;
  const double at_output = report->hole_score / std::pow(measured_scale, 3);
  const double score = at_output / ThinHoleBias(std::min(1.0, measured_scale));
  const std::lock_guard<std::mutex> lock(mutex_);
  remembered_.push_back({output_camera, cam_from_world, score});
  if (remembered_.size() > kRemembered) remembered_.pop_front();
  return score;
}

int CoverageProbe::calls() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return calls_;
}

double CoverageProbe::ms() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return ms_;
}

StatusOr<bool> CoverageProbe::Valid(const CameraModel& output_camera, const Rigid3& cam_from_world) {
  PX_ASSIGN_OR_RETURN(double score, HoleScore(output_camera, cam_from_world));
  return score < valid_hole_score_;
}

}  // namespace px::direct
