#include "eval/real/leave_one_out.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "eval/real/contact_sheet.h"
#include "eval/render/image_metrics.h"
#include "pipeline/calib/photometric.h"
#include "pipeline/depth/depth_stage.h"
#include "pipeline/direct/scene_geometry.h"
#include "pipeline/render/cpu_scene_renderer.h"
#include "pipeline/run/capture_calibration.h"
#include "pipeline/run/image_set_scale.h"

namespace px::eval {
namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

void Progress(const LeaveOneOutOptions& options, const std::string& line) {
  if (options.progress) options.progress(line);
}

ImageScores Score(const cv::Mat& image, const cv::Mat& photo, const cv::Mat& edge_band) {
  ImageScores scores;
  scores.psnr_db = Psnr(image, photo);
  scores.ssim = Ssim(image, photo);
  scores.psnr_edges_db = cv::countNonZero(edge_band) > 0 ? Psnr(image, photo, edge_band) : scores.psnr_db;
  return scores;
}

// The plane 1/z = a x + b y + c (x, y pixels of `depth`'s view) that fits its confident depth
// best: least squares reweighted (Cauchy) so that the background or a near object does not pull
// it. Falls back to the median depth, fronto-parallel.
Eigen::Vector3d FitInverseDepthPlane(const DepthMap& depth) {
  std::vector<Eigen::Vector3d> rows;
  std::vector<double> inverse;
  const int step = std::max(1, static_cast<int>(std::sqrt(depth.depth_m.total() / 20000.0)));
  for (int pass = 0; pass < 2 && rows.size() < 100; ++pass) {
    rows.clear();
    inverse.clear();
    for (int y = 0; y < depth.depth_m.rows; y += step) {
      for (int x = 0; x < depth.depth_m.cols; x += step) {
        const float z = depth.depth_m.at<float>(y, x);
        const bool confident = depth.confidence.empty() || depth.confidence.at<float>(y, x) >= 0.5f;
        if (!(z > 0) || !std::isfinite(z) || (pass == 0 && !confident)) continue;
        rows.emplace_back(x, y, 1.0);
        inverse.push_back(1.0 / z);
      }
    }
  }
  if (rows.empty()) return Eigen::Vector3d(0, 0, 1);
  std::vector<double> sorted = inverse;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
  Eigen::Vector3d plane(0, 0, sorted[sorted.size() / 2]);
  for (int iteration = 0; iteration < 10; ++iteration) {
    std::vector<double> residuals(rows.size());
    for (size_t i = 0; i < rows.size(); ++i) residuals[i] = std::abs(rows[i].dot(plane) - inverse[i]);
    std::vector<double> spread = residuals;
    std::nth_element(spread.begin(), spread.begin() + static_cast<long>(spread.size() / 2), spread.end());
    const double scale = std::max(1.4826 * spread[spread.size() / 2], 1e-9);
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < rows.size(); ++i) {
      const double r = residuals[i] / (2 * scale);
      const double w = 1.0 / (1.0 + r * r);
      normal += w * rows[i] * rows[i].transpose();
      rhs += w * inverse[i] * rows[i];
    }
    const Eigen::Vector3d next = normal.ldlt().solve(rhs);
    if (!next.allFinite()) break;
    plane = next;
  }
  return plane;
}

// The nearest view's image as the held-out camera sees it through the plane 1/z = p . (x, y, 1)
// of the nearest view's pixels.
cv::Mat WarpByPlane(const View& from, const Eigen::Vector3d& inverse_depth_plane, const View& to) {
  // On the plane, n^T X = 1 in `from`'s camera frame with n = K^T p.
  const Eigen::Vector3d n = from.camera.K().transpose() * inverse_depth_plane;
  const Rigid3 to_from_from = to.cam_from_world * from.cam_from_world.Inverse();
  const Eigen::Matrix3d h = to.camera.K() * (to_from_from.RotationMatrix() + to_from_from.translation * n.transpose()) *
                            from.camera.K().inverse();
  cv::Matx33d homography;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) homography(r, c) = h(r, c);
  }
  cv::Mat warped;
  cv::warpPerspective(from.image, warped, homography, to.image.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return warped;
}

cv::Mat ResizedTo(const cv::Mat& image, cv::Size size) {
  if (image.size() == size) return image;
  cv::Mat resized;
  cv::resize(image, resized, size, 0, 0, cv::INTER_AREA);
  return resized;
}

cv::Mat ErrorImage(const cv::Mat& image, const cv::Mat& photo) {
  cv::Mat error;
  cv::absdiff(image, photo, error);
  error.convertTo(error, CV_8UC3, 4.0);
  return error;
}

Status DumpCase(const LeaveOneOutOptions& options,
                const std::string& set,
                const LeaveOneOutCase& c,
                const cv::Mat& photo,
                const cv::Mat& ours,
                const cv::Mat& nearest,
                const cv::Mat& plane,
                const cv::Mat& edge_band) {
  char psnr[3][64];
  std::snprintf(psnr[0], sizeof(psnr[0]), "ours %.2f dB", c.ours.psnr_db);
  std::snprintf(psnr[1], sizeof(psnr[1]), "nearest (view %d) %.2f dB", c.nearest_view, c.nearest.psnr_db);
  std::snprintf(psnr[2], sizeof(psnr[2]), "plane %.2f dB", c.plane.psnr_db);
  cv::Mat band;
  cv::cvtColor(edge_band, band, cv::COLOR_GRAY2BGR);
  const std::vector<LabelledImage> cells = {{photo, "photo " + c.view_name},
                                            {ours, psnr[0]},
                                            {nearest, psnr[1]},
                                            {plane, psnr[2]},
                                            {band, "edge band"},
                                            {ErrorImage(ours, photo), "ours error x4"},
                                            {ErrorImage(nearest, photo), "nearest error x4"},
                                            {ErrorImage(plane, photo), "plane error x4"}};
  const cv::Mat sheet = ContactSheet(cells, 4, 480);
  const std::filesystem::path file =
      options.dump_dir / (SafeFileName(set) + "_loo_view" + std::to_string(c.view) + ".png");
  return WritePng(file, sheet);
}

}  // namespace

ImageScores MeanScores(const std::vector<LeaveOneOutCase>& cases, ImageScores LeaveOneOutCase::*which) {
  ImageScores mean;
  if (cases.empty()) return mean;
  for (const LeaveOneOutCase& c : cases) {
    mean.psnr_db += (c.*which).psnr_db;
    mean.ssim += (c.*which).ssim;
    mean.psnr_edges_db += (c.*which).psnr_edges_db;
  }
  const double n = static_cast<double>(cases.size());
  mean.psnr_db /= n;
  mean.ssim /= n;
  mean.psnr_edges_db /= n;
  return mean;
}

LeaveOneOutMeans Means(const LeaveOneOutResult& result) {
  LeaveOneOutMeans means;
  means.ours = MeanScores(result.cases, &LeaveOneOutCase::ours);
  means.nearest = MeanScores(result.cases, &LeaveOneOutCase::nearest);
  means.plane = MeanScores(result.cases, &LeaveOneOutCase::plane);
  for (const LeaveOneOutCase& c : result.cases) means.invented += c.invented / static_cast<double>(result.cases.size());
  return means;
}

StatusOr<LeaveOneOutResult> EvaluateLeaveOneOut(const RealSet& set, const LeaveOneOutOptions& options) {
  LeaveOneOutResult result;
  result.set = set.name;
  const bool lattice_photo = set.capture.kind == FrameSetKind::kLatticeFrame;
  result.num_views = static_cast<int>(set.capture.frames.size());
  if (!lattice_photo && result.num_views < 3) {
    return FailedPreconditionError(set.name + ": " + std::to_string(result.num_views) +
                                   " views; leaving one out needs at least 3");
  }
  // The product's working size and calibration, all views together.
  const std::optional<WorkingImageSet> working =
      ImageSetAtWorkingSize(options.max_side_px, set.capture, RigCalibration{});
  const FrameSet& capture = working ? working->capture : set.capture;
  if (working) result.notes.push_back(working->note);
  Progress(options, set.name + ": structure from motion on " + std::to_string(result.num_views) + " views");
  std::vector<std::string> warnings;
  std::vector<StageTiming> timings;
  StatusOr<CalibratedViews> calibrated = CalibrateCapture(capture,
                                                          RigCalibration{},
                                                          CalibOptions{},
                                                          calib::RigRefinementOptions{},
                                                          options.sfm,
                                                          &warnings,
                                                          &timings,
                                                          set.lattice);
  if (!calibrated.ok()) {
    return FailedPreconditionError(set.name + ": not posed (" + calibrated.status().message() + ")");
  }
  std::vector<View>& views = calibrated->views;
  if (options.photometric.enabled && views.size() >= 2) {
    StatusOr<calib::PhotometricReport> equalised =
        calib::EqualisePhotometry(&views, direct::CentreViewIndex(views), options.photometric);
    result.notes.push_back(equalised.ok() ? "photometric: " + equalised->Summary()
                                          : "photometric equalisation skipped: " + equalised.status().message());
  }
  result.num_posed = static_cast<int>(views.size());
  std::vector<int> held_out = set.held_out;
  if (lattice_photo) {  // its views are its tiles, known now
    result.num_views = result.num_posed;
    held_out = HeldOutViews(result.num_posed);
  }
  result.calibration = calibrated->calibration + (calibrated->summary.empty() ? "" : ": " + calibrated->summary);
  if (result.num_posed < 3) {
    return FailedPreconditionError(set.name + ": only " + std::to_string(result.num_posed) + " of " +
                                   std::to_string(result.num_views) + " views posed; leaving one out needs 3");
  }
  for (const std::string& warning : warnings) result.notes.push_back(warning);
  const DepthOptions depth_options =
      options.depth.WithDefaultDepthRange(calibrated->depth_min_m, calibrated->depth_max_m);

  for (int held : held_out) {
    const auto target = std::find_if(views.begin(), views.end(), [&](const View& v) { return v.id.value == held; });
    const std::string view_name = lattice_photo                                    ? "tile " + std::to_string(held)
                                  : held < static_cast<int>(set.view_names.size()) ? set.view_names[held]
                                                                                   : "";
    if (target == views.end()) {
      result.notes.push_back("view " + std::to_string(held) + " (" + view_name + ") was not posed: not scored");
      continue;
    }
    std::vector<View> sources;
    for (const View& view : views) {
      if (view.id.value != held) sources.push_back(view);
    }
    LeaveOneOutCase c;
    c.view = held;
    c.view_name = view_name;
    c.num_sources = static_cast<int>(sources.size());
    Progress(options,
             set.name + ": view " + std::to_string(held) + " held out: depth for " + std::to_string(sources.size()) +
                 " views");
    Clock::time_point start = Clock::now();
    PX_ASSIGN_OR_RETURN(DepthStageResult depth, ComputeLayeredDepth(sources, depth_options));
    c.depth_ms = MsSince(start);
    PX_ASSIGN_OR_RETURN(std::unique_ptr<CpuSceneRenderer> renderer,
                        CpuSceneRenderer::Create(sources, depth.layered, options.render));
    VirtualCamera camera;
    camera.camera = target->camera;
    camera.cam_from_world = target->cam_from_world;
    start = Clock::now();
    PX_ASSIGN_OR_RETURN(FrameRender frame, renderer->Render(camera));
    c.render_ms = MsSince(start);
    const cv::Mat& photo = target->image;

    // The baselines' source: the nearest other camera centre.
    const Eigen::Vector3d centre = CameraCentre(target->cam_from_world);
    size_t nearest = 0;
    double nearest_distance = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < sources.size(); ++i) {
      const double distance = (CameraCentre(sources[i].cam_from_world) - centre).norm();
      if (distance < nearest_distance) {
        nearest_distance = distance;
        nearest = i;
      }
    }
    c.nearest_view = sources[nearest].id.value;
    const cv::Mat nearest_image = ResizedTo(sources[nearest].image, photo.size());
    const cv::Mat plane_image = WarpByPlane(sources[nearest], FitInverseDepthPlane(depth.maps[nearest]), *target);

    const cv::Mat edge_band = DepthEdgeBand(frame.depth_m, options.edge_band_px);
    c.edge_band = static_cast<double>(cv::countNonZero(edge_band)) / static_cast<double>(edge_band.total());
    c.ours = Score(frame.bgr, photo, edge_band);
    c.nearest = Score(nearest_image, photo, edge_band);
    c.plane = Score(plane_image, photo, edge_band);
    c.invented = frame.holes.hole_ratio;
    if (!options.dump_dir.empty()) {
      PX_RETURN_IF_ERROR(DumpCase(options, set.name, c, photo, frame.bgr, nearest_image, plane_image, edge_band));
    }
    result.cases.push_back(c);
  }
  return result;
}

}  // namespace px::eval
