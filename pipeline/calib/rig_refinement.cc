#include "pipeline/calib/rig_refinement.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/core/utility.hpp>

#include "pipeline/calib/absolute_pose.h"
#include "pipeline/calib/bundle_adjustment.h"
#include "pipeline/calib/relative_pose.h"
#include "pipeline/calib/tracks.h"
#include "pipeline/calib/triangulation.h"
#include "pipeline/core/order_statistics.h"
#include "pipeline/core/stage_clock.h"

namespace px::calib {
namespace {

// Below this many features a view cannot contribute (P3P and a few tracks need more).
constexpr int kMinFeaturesPerView = 30;
// Below this many descriptor matches a pair is not worth a RANSAC.
constexpr int kMinPairMatches = 16;
// A factory calibration whose reprojection RMS on the shot is at most this (pixels) fits it:
// refinement that cannot improve on it leaves it without a warning.
constexpr double kFactoryFitsRmsPx = 1.0;

std::string Format(const char* format, double a, double b = 0, double c = 0) {
  char text[256];
  std::snprintf(text, sizeof(text), format, a, b, c);
  return text;
}

// The smallest distance between two lens centres (the lattice spacing).
double SmallestSpacing(const RigCalibration& rig) {
  double spacing = std::numeric_limits<double>::infinity();
  for (int i = 0; i < rig.NumViews(); ++i) {
    for (int j = i + 1; j < rig.NumViews(); ++j) {
      const double d = (CameraCentre(rig.lenses[i].cam_from_rig) - CameraCentre(rig.lenses[j].cam_from_rig)).norm();
      if (d > 0) spacing = std::min(spacing, d);
    }
  }
  return std::isfinite(spacing) ? spacing : 0.0;
}

struct ViewData {
  Features features;
  std::vector<Eigen::Vector3d> rays;            // unit-depth rays through the factory lens
  std::vector<Eigen::Vector2d> undistorted_px;  // the same in the factory pinhole's pixels
  bool usable = false;
};

// Matches one lens pair inside the factory's epipolar band and verifies it with five-point RANSAC.
PairMatches MatchPair(const ViewData& a,
                      const ViewData& b,
                      int ia,
                      int ib,
                      const RigCalibration& factory,
                      const RigRefinementOptions& options,
                      uint64_t seed,
                      PairRefinement* figures) {
  PairMatches verified{ia, ib, {}};
  figures->view_a = ia;
  figures->view_b = ib;
  const Rigid3 b_from_a = factory.lenses[ib].cam_from_rig * factory.lenses[ia].cam_from_rig.Inverse();
  const std::vector<std::vector<int>> candidates = EpipolarCandidates(a.rays,
                                                                      b.undistorted_px,
                                                                      b_from_a,
                                                                      factory.lenses[ib].camera.WithoutDistortion().K(),
                                                                      0.5 * factory.nominal_depth_min_m,
                                                                      options.epipolar_tolerance_px);
  const std::vector<FeatureMatch> matches = MatchCandidates(a.features, b.features, candidates, options.matching);
  figures->matches = static_cast<int>(matches.size());
  if (figures->matches < kMinPairMatches) return verified;
  std::vector<Eigen::Vector3d> rays_a, rays_b;
  for (const FeatureMatch& m : matches) {
    rays_a.push_back(a.rays[m.a]);
    rays_b.push_back(b.rays[m.b]);
  }
  RansacOptions ransac = options.ransac;
  ransac.seed = seed;
  const RelativePoseResult pose = EstimateRelativePose(rays_a, rays_b, RelativePoseSolver::kFivePoint, ransac);
  if (!pose.success) return verified;
  figures->inliers = static_cast<int>(pose.inliers.size());
  figures->median_parallax_px = pose.median_parallax_px;
  figures->median_epipolar_error_px = pose.median_epipolar_error_px;
  figures->homography_fraction = pose.homography_inlier_fraction;
  figures->homography_ratio = pose.HomographyRatio();
  for (int i : pose.inliers) verified.matches.push_back(matches[i]);
  return verified;
}

// Up to `max_tracks` of `tracks`: the longest first, taken in turn from the cells of a 6x6 grid
// over the image of each track's first view, so that the kept points cover the field (where
// focal length and principal point show).
std::vector<Track> SelectTracks(std::vector<Track> tracks,
                                const std::vector<ViewData>& views,
                                const RigCalibration& rig,
                                int max_tracks) {
  if (static_cast<int>(tracks.size()) <= max_tracks) return tracks;
  std::stable_sort(tracks.begin(), tracks.end(), [](const Track& a, const Track& b) {
    return a.observations.size() > b.observations.size();
  });
  constexpr int kCells = 6;
  std::vector<std::vector<int>> cells(kCells * kCells);
  for (size_t t = 0; t < tracks.size(); ++t) {
    const TrackObservation& first = tracks[t].observations.front();
    const Eigen::Vector2d& px = views[first.view].features.keypoints_px[first.feature];
    const CameraModel& camera = rig.lenses[first.view].camera;
    const int cx = std::clamp(static_cast<int>(px.x() * kCells / camera.width), 0, kCells - 1);
    const int cy = std::clamp(static_cast<int>(px.y() * kCells / camera.height), 0, kCells - 1);
    cells[cy * kCells + cx].push_back(static_cast<int>(t));
  }
  std::vector<Track> selected;
  for (size_t round = 0; static_cast<int>(selected.size()) < max_tracks; ++round) {
    bool any = false;
    for (const std::vector<int>& cell : cells) {
      if (round >= cell.size() || static_cast<int>(selected.size()) >= max_tracks) continue;
      selected.push_back(tracks[cell[round]]);
      any = true;
    }
    if (!any) break;
  }
  return selected;
}

// The factory calibration's lens as a bundle-adjustment camera.
BaCamera FactoryCamera(const LensCalibration& lens) {
  BaCamera camera;
  camera.camera = lens.camera;
  camera.cam_from_world = lens.cam_from_rig;
  return camera;
}

// Drops observations whose point is seen by fewer than two cameras, and unobserved points.
void PruneProblem(BaProblem* problem) {
  std::vector<int> count(problem->points.size(), 0);
  for (const BaObservation& o : problem->observations) ++count[o.point];
  std::vector<int> new_index(problem->points.size(), -1);
  std::vector<Eigen::Vector3d> points;
  for (size_t p = 0; p < problem->points.size(); ++p) {
    if (count[p] < 2) continue;
    new_index[p] = static_cast<int>(points.size());
    points.push_back(problem->points[p]);
  }
  std::vector<BaObservation> observations;
  for (BaObservation o : problem->observations) {
    if (new_index[o.point] < 0) continue;
    o.point = new_index[o.point];
    observations.push_back(o);
  }
  problem->points = std::move(points);
  problem->observations = std::move(observations);
}

// The reprojection RMS the factory calibration achieves on `problem`'s observations: cameras
// held, points re-adjusted.
StatusOr<double> FactoryRms(const BaProblem& problem, const RigCalibration& factory, int num_threads) {
  BaProblem held = problem;
  for (size_t c = 0; c < held.cameras.size(); ++c) held.cameras[c] = FactoryCamera(factory.lenses[c]);
  BundleAdjustmentOptions options;
  options.refine_poses = false;
  options.refine_focal = false;
  options.num_threads = num_threads;
  PX_ASSIGN_OR_RETURN(BundleAdjustmentReport report, BundleAdjust(&held, {}, options));
  return report.final_rms_px;
}

// The tiles must fit the rig: one per lens, each of its lens's size.
Status CheckTiles(const std::vector<cv::Mat>& upright_tiles, const RigCalibration& factory) {
  const int n = factory.NumViews();
  if (static_cast<int>(upright_tiles.size()) != n) {
    return InvalidArgumentError("rig refinement: got " + std::to_string(upright_tiles.size()) + " tiles, rig '" +
                                factory.rig_name + "' has " + std::to_string(n) + " lenses");
  }
  for (int i = 0; i < n; ++i) {
    const CameraModel& camera = factory.lenses[i].camera;
    if (upright_tiles[i].cols != camera.width || upright_tiles[i].rows != camera.height) {
      return InvalidArgumentError("rig refinement: view " + std::to_string(i) + " is " +
                                  std::to_string(upright_tiles[i].cols) + "x" + std::to_string(upright_tiles[i].rows) +
                                  ", lens intrinsics are for " + std::to_string(camera.width) + "x" +
                                  std::to_string(camera.height));
    }
  }
  return OkStatus();
}

// 1. Each view's features with their rays through its factory lens; a view with too few to contribute is
// noted (with what its exposure suggests) and not used.
std::vector<ViewData> ViewsThroughFactoryLenses(std::vector<Features> features,
                                                const std::vector<cv::Mat>& upright_tiles,
                                                const RigCalibration& factory,
                                                std::vector<ViewRefinement>* view_reports) {
  const int n = factory.NumViews();
  std::vector<ViewData> views(n);
  for (int i = 0; i < n; ++i) {
    ViewData& view = views[i];
    view.features = std::move(features[i]);
    const CameraModel& camera = factory.lenses[i].camera;
    for (const Eigen::Vector2d& px : view.features.keypoints_px) {
      const Eigen::Vector3d ray = camera.Unproject(px);
      view.rays.push_back(ray);
      view.undistorted_px.emplace_back(camera.fx * ray.x() + camera.cx, camera.fy * ray.y() + camera.cy);
    }
    (*view_reports)[i].features = view.features.size();
    view.usable = view.features.size() >= kMinFeaturesPerView;
    if (!view.usable) {
      (*view_reports)[i].note = std::to_string(view.features.size()) + " features: the view is " +
                                DescribeFewFeatures(MeasureExposure(upright_tiles[i]));
    }
  }
  return views;
}

// How many views have features enough to contribute.
int CountUsable(const std::vector<ViewData>& views) {
  int usable_views = 0;
  for (const ViewData& view : views) usable_views += view.usable ? 1 : 0;
  return usable_views;
}

// Why fewer than two views can contribute, with the most features any view has.
std::string TooFewFeaturesReason(const std::vector<ViewData>& views,
                                 int usable_views,
                                 const std::vector<cv::Mat>& upright_tiles) {
  const int n = static_cast<int>(views.size());
  int best = 0;
  for (int i = 0; i < n; ++i) best = std::max(best, views[i].features.size());
  return "too few features: " + std::to_string(usable_views) + " of " + std::to_string(n) + " views have " +
         std::to_string(kMinFeaturesPerView) + " or more (at most " + std::to_string(best) + "; view 0 is " +
         DescribeFewFeatures(MeasureExposure(upright_tiles[0])) + ")";
}

// 2. The pairs of usable lenses close enough to see much of the same scene: at most
// options.max_pair_distance_spacings lattice spacings apart.
std::vector<std::pair<int, int>> NearbyPairs(const std::vector<ViewData>& views,
                                             const RigCalibration& factory,
                                             double spacing,
                                             const RigRefinementOptions& options) {
  const int n = factory.NumViews();
  std::vector<std::pair<int, int>> pair_list;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      const double d =
          (CameraCentre(factory.lenses[i].cam_from_rig) - CameraCentre(factory.lenses[j].cam_from_rig)).norm();
      if (views[i].usable && views[j].usable && d <= options.max_pair_distance_spacings * spacing * (1 + 1e-9)) {
        pair_list.emplace_back(i, j);
      }
    }
  }
  return pair_list;
}

// The RANSAC options of the pairs and the P3P: the given ones at the lenses' mean focal length.
RansacOptions RigRansac(const RigCalibration& factory, const RigRefinementOptions& options) {
  const int n = factory.NumViews();
  RansacOptions ransac = options.ransac;
  double mean_focal = 0;
  for (const LensCalibration& lens : factory.lenses) mean_focal += lens.camera.fx / n;
  ransac.focal_px = mean_focal;
  return ransac;
}

// What matching the lens pairs found: each pair's verified matches, and its figures for the report.
struct PairMatching {
  std::vector<PairMatches> verified;
  std::vector<PairRefinement> figures;
};

// Matches and verifies the pairs in parallel, each with its own seed so that the result does not depend on
// the schedule.
PairMatching MatchNearbyPairs(const std::vector<ViewData>& views,
                              const std::vector<std::pair<int, int>>& pair_list,
                              const RigCalibration& factory,
                              const RansacOptions& ransac,
                              const RigRefinementOptions& options) {
  RigRefinementOptions pair_options = options;
  pair_options.ransac = ransac;
  PairMatching matching;
  matching.verified.resize(pair_list.size());
  matching.figures.resize(pair_list.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(pair_list.size())), [&](const cv::Range& range) {
    for (int p = range.start; p < range.end; ++p) {
      const auto [a, b] = pair_list[p];
      matching.verified[p] = MatchPair(
          views[a], views[b], a, b, factory, pair_options, options.seed * 1000003ULL + p, &matching.figures[p]);
    }
  });
  return matching;
}

// Sums the pairs' figures; the lens centres are held when a homography explains the median pair's matches
// (a plane, or a scene too far for the baseline), as the scene cannot fix them.
void SummarisePairs(const RigRefinementOptions& options, RigRefinementReport* report) {
  report->num_pairs = static_cast<int>(report->pairs.size());
  std::vector<double> homography_ratios;
  for (const PairRefinement& pair : report->pairs) {
    report->num_matches += pair.matches;
    report->num_inliers += pair.inliers;
    if (pair.inliers >= kMinPairMatches) homography_ratios.push_back(pair.homography_ratio);
  }
  report->median_homography_ratio = Median(homography_ratios);
  report->centres_held =
      !homography_ratios.empty() && report->median_homography_ratio < options.planar_homography_ratio;
}

// 3. Tracks through the verified matches (a selection that covers the field), triangulated with the factory
// calibration; a point that fails to triangulate or lies behind a lens is dropped.
BaProblem TriangulateWithFactory(const std::vector<ViewData>& views,
                                 const std::vector<PairMatches>& verified,
                                 const RigCalibration& factory,
                                 const RigRefinementOptions& options) {
  const int n = factory.NumViews();
  std::vector<int> feature_counts(n);
  for (int i = 0; i < n; ++i) feature_counts[i] = views[i].features.size();
  const std::vector<Track> tracks =
      SelectTracks(BuildTracks(feature_counts, verified), views, factory, options.max_tracks);
  BaProblem problem;
  for (int i = 0; i < n; ++i) problem.cameras.push_back(FactoryCamera(factory.lenses[i]));
  for (const Track& track : tracks) {
    std::vector<Rigid3> poses;
    std::vector<Eigen::Vector3d> rays;
    for (const TrackObservation& o : track.observations) {
      poses.push_back(factory.lenses[o.view].cam_from_rig);
      rays.push_back(views[o.view].rays[o.feature]);
    }
    const std::optional<Eigen::Vector3d> point = TriangulatePoint(poses, rays);
    if (!point) continue;
    bool in_front = true;
    for (const Rigid3& pose : poses) in_front = in_front && (pose * *point).z() > 0;
    if (!in_front) continue;
    const int index = static_cast<int>(problem.points.size());
    problem.points.push_back(*point);
    for (const TrackObservation& o : track.observations) {
      problem.observations.push_back({o.view, index, views[o.view].features.keypoints_px[o.feature]});
    }
  }
  return problem;
}

// 4. P3P per view against the points: drops the observations that disagree with the rest of their view, then
// the points left with fewer than two.
void KeepP3pInliers(const RigCalibration& factory,
                    const RansacOptions& ransac,
                    const RigRefinementOptions& options,
                    BaProblem* problem_ptr) {
  BaProblem& problem = *problem_ptr;
  const int n = factory.NumViews();
  std::vector<std::vector<int>> observations_of_view(n);
  for (size_t k = 0; k < problem.observations.size(); ++k)
    observations_of_view[problem.observations[k].camera].push_back(k);
  std::vector<char> keep(problem.observations.size(), 1);
  RansacOptions p3p = ransac;
  p3p.max_error_px = std::max(2.0 * ransac.max_error_px, 4.0);  // the points carry the factory's errors
  for (int v = 0; v < n; ++v) {
    std::vector<Eigen::Vector3d> rays, points;
    for (int k : observations_of_view[v]) {
      const BaObservation& o = problem.observations[k];
      rays.push_back(factory.lenses[v].camera.Unproject(o.pixel));
      points.push_back(problem.points[o.point]);
    }
    p3p.seed = options.seed * 7919ULL + v;
    const AbsolutePoseResult pose = EstimateAbsolutePose(rays, points, AbsolutePoseSolver::kP3p, p3p);
    std::vector<char> inlier(rays.size(), 0);
    if (pose.success) {
      for (int i : pose.inliers) inlier[i] = 1;
    }
    for (size_t i = 0; i < rays.size(); ++i) keep[observations_of_view[v][i]] = inlier[i];
  }
  std::vector<BaObservation> kept;
  for (size_t k = 0; k < problem.observations.size(); ++k) {
    if (keep[k]) kept.push_back(problem.observations[k]);
  }
  problem.observations = std::move(kept);
  PruneProblem(&problem);
}

// How many of `problem`'s observations each of its n views has.
std::vector<int> ObservationsPerView(const BaProblem& problem, int n) {
  std::vector<int> observations_per_view(n, 0);
  for (const BaObservation& o : problem.observations) ++observations_per_view[o.camera];
  return observations_per_view;
}

// The views held at the factory calibration, and how many are left to refine.
struct HeldViews {
  std::vector<char> held;
  int refinable = 0;
};

// Views with too few observations keep the factory calibration and leave the adjustment: noted (with what
// their exposure suggests), their observations dropped, and the points left with fewer than two.
HeldViews HoldSparseViews(const std::vector<cv::Mat>& upright_tiles,
                          const RigRefinementOptions& options,
                          BaProblem* problem,
                          std::vector<ViewRefinement>* view_reports) {
  const int n = static_cast<int>(view_reports->size());
  const std::vector<int> observations_per_view = ObservationsPerView(*problem, n);
  HeldViews held_views;
  held_views.held.assign(n, 0);
  for (int v = 0; v < n; ++v) {
    if (observations_per_view[v] >= options.min_observations_per_view) {
      ++held_views.refinable;
      continue;
    }
    held_views.held[v] = 1;
    ViewRefinement& view = (*view_reports)[v];
    if (view.note.empty()) {
      const std::string exposure = DescribeExposureProblem(MeasureExposure(upright_tiles[v]));
      view.note =
          std::to_string(observations_per_view[v]) + " matched points (need " +
          std::to_string(options.min_observations_per_view) + "): the view shares too little with its neighbours (" +
          (exposure.empty() ? "a different scene, or a lens far off its calibration?" : "it is " + exposure) + ")";
    }
  }
  std::erase_if(problem->observations, [&](const BaObservation& o) { return held_views.held[o.camera] != 0; });
  PruneProblem(problem);
  return held_views;
}

// Why the shot cannot refine the rig: too few points or refinable views, with the matching figures.
std::string TooFewMatchesReason(const BaProblem& problem,
                                int refinable,
                                const RigRefinementOptions& options,
                                const RigRefinementReport& report) {
  const int n = static_cast<int>(report.views.size());
  return "too few matches to refine: " + std::to_string(problem.points.size()) + " points seen by two or " +
         "more lenses (need " + std::to_string(options.min_tracks) + "), " + std::to_string(refinable) + " of " +
         std::to_string(n) + " views with " + std::to_string(options.min_observations_per_view) + "+ observations; " +
         std::to_string(report.num_matches) + " matches, " + std::to_string(report.num_inliers) +
         " RANSAC inliers over " + std::to_string(report.num_pairs) + " lens pairs";
}

// 5. The factory calibration of each lens to refine as its prior: pose, focal length, principal point.
std::vector<BaPrior> FactoryPriors(const RigCalibration& factory,
                                   const std::vector<char>& held,
                                   double spacing,
                                   const RigRefinementOptions& options) {
  const int n = factory.NumViews();
  std::vector<BaPrior> priors;
  for (int v = 0; v < n; ++v) {
    if (held[v]) continue;
    const LensCalibration& lens = factory.lenses[v];
    BaPrior prior;
    prior.camera = v;
    prior.cam_from_world = lens.cam_from_rig;
    prior.rotation_sigma_deg = options.rotation_sigma_deg;
    prior.centre_sigma_m = options.centre_sigma_spacings * spacing;
    prior.focal_px = lens.camera.fx;
    prior.focal_sigma_relative = options.focal_sigma_relative;
    prior.cx = lens.camera.cx;
    prior.cy = lens.camera.cy;
    prior.principal_point_sigma_px = options.principal_point_sigma_px;
    priors.push_back(prior);
  }
  return priors;
}

// The reports of the two adjustment passes.
struct AdjustmentPasses {
  BundleAdjustmentReport first;
  BundleAdjustmentReport second;
};

// Bundle adjustment twice: a short first pass finds the outliers, which are dropped (with the points left
// with fewer than two observations) before the second.
StatusOr<AdjustmentPasses> AdjustTwice(const std::vector<BaPrior>& priors,
                                       bool centres_held,
                                       const RigRefinementOptions& options,
                                       BaProblem* problem) {
  BundleAdjustmentOptions adjustment;
  adjustment.refine_centres = !centres_held;
  adjustment.refine_principal_point = options.refine_principal_point;
  adjustment.refine_radial = options.refine_radial_distortion;
  adjustment.loss_scale_px = options.loss_scale_px;
  adjustment.num_threads = options.num_threads;
  // The first pass only has to find the outliers.
  BundleAdjustmentOptions first_pass = adjustment;
  first_pass.max_iterations = 15;
  AdjustmentPasses passes;
  PX_ASSIGN_OR_RETURN(passes.first, BundleAdjust(problem, priors, first_pass));
  const std::vector<double> errors = ReprojectionErrors(*problem);
  std::vector<BaObservation> kept;
  for (size_t k = 0; k < errors.size(); ++k) {
    if (errors[k] <= options.outlier_error_px) kept.push_back(problem->observations[k]);
  }
  problem->observations = std::move(kept);
  PruneProblem(problem);
  PX_ASSIGN_OR_RETURN(passes.second, BundleAdjust(problem, priors, adjustment));
  return passes;
}

// The refined calibration, and its first implausible change ("" when every change is plausible).
struct RefinedRig {
  RigCalibration rig;
  std::string implausible;
};

// 6. Takes each refined lens from the adjustment and measures how far it moved from the factory calibration
// (per view and the largest), naming the first change beyond what is plausible.
RefinedRig CompareWithFactory(const RigCalibration& factory,
                              const BaProblem& problem,
                              const std::vector<char>& held,
                              const std::vector<int>& observations_per_view,
                              double spacing,
                              const RigRefinementOptions& options,
                              RigRefinementReport* report) {
  const int n = factory.NumViews();
  RefinedRig refined{factory, ""};
  std::string& implausible = refined.implausible;
  for (int v = 0; v < n; ++v) {
    ViewRefinement& view = report->views[v];
    view.observations = observations_per_view[v];
    if (held[v]) continue;
    const LensCalibration& before = factory.lenses[v];
    LensCalibration& after = refined.rig.lenses[v];
    after.camera = problem.cameras[v].camera;
    after.cam_from_rig = problem.cameras[v].cam_from_world;
    view.refined = true;
    view.rotation_change_deg = RotationErrorDeg(after.cam_from_rig, before.cam_from_rig);
    view.centre_change_m = (CameraCentre(after.cam_from_rig) - CameraCentre(before.cam_from_rig)).norm();
    view.focal_change_relative = after.camera.fx / before.camera.fx - 1;
    view.principal_point_change_px = std::hypot(after.camera.cx - before.camera.cx, after.camera.cy - before.camera.cy);
    report->max_rotation_change_deg = std::max(report->max_rotation_change_deg, view.rotation_change_deg);
    report->max_centre_change_m = std::max(report->max_centre_change_m, view.centre_change_m);
    report->max_focal_change_relative =
        std::max(report->max_focal_change_relative, std::abs(view.focal_change_relative));
    if (!implausible.empty()) continue;
    if (view.rotation_change_deg > options.max_rotation_change_deg) {
      implausible = Format("lens %.0f turned by %.2f deg (more than %.2f deg is not plausible)",
                           v,
                           view.rotation_change_deg,
                           options.max_rotation_change_deg);
    } else if (view.centre_change_m > options.max_centre_change_spacings * spacing) {
      implausible = Format("lens %.0f moved by %.2f mm (more than %.2f mm is not plausible)",
                           v,
                           1000 * view.centre_change_m,
                           1000 * options.max_centre_change_spacings * spacing);
    } else if (std::abs(view.focal_change_relative) > options.max_focal_change_relative) {
      implausible = Format("lens %.0f changed focal length by %.1f %% (more than %.1f %% is not plausible)",
                           v,
                           100 * view.focal_change_relative,
                           100 * options.max_focal_change_relative);
    }
  }
  return refined;
}

// Warnings for what keeps the factory calibration in part: each noted view, and held lens centres.
void AddHoldWarnings(RigRefinementReport* report) {
  const int n = static_cast<int>(report->views.size());
  for (int v = 0; v < n; ++v) {
    if (!report->views[v].note.empty()) {
      report->warnings.push_back("view " + std::to_string(v) + ": " + report->views[v].note +
                                 "; it keeps its factory calibration");
    }
  }
  if (report->centres_held) {
    report->warnings.push_back(
        Format("the scene is planar or too far for the baseline (one homography explains the "
               "matches of the median lens pair to %.1f times their noise): lens centres are "
               "held at the factory calibration",
               report->median_homography_ratio));
  }
}

// Why the factory calibration is kept, or "" to use the refined one: a failed adjustment, an implausible
// change, or no measurable gain (then report->factory_fits says whether the factory calibration fits).
std::string FallbackReason(const std::string& adjustment_message,
                           const std::string& implausible,
                           const RigRefinementOptions& options,
                           RigRefinementReport* report) {
  if (!std::isfinite(report->rms_after_px) || !std::isfinite(report->rms_before_px)) {
    return "bundle adjustment failed: " + adjustment_message;
  }
  if (!implausible.empty()) return "implausible change: " + implausible;
  if (!(report->rms_before_px - report->rms_after_px >= options.min_rms_gain_px)) {
    // No measurable gain. When the factory calibration explains the matches to within a pixel
    // the lenses have not measurably moved: not a failure, and no warning is due.
    report->factory_fits = report->rms_before_px <= kFactoryFitsRmsPx;
    if (report->factory_fits) {
      return Format("the factory calibration already fits the shot (reprojection RMS %.3f px; refined %.3f px)",
                    report->rms_before_px,
                    report->rms_after_px);
    }
    return Format(
        "refinement did not lower the reprojection error (%.3f px with the factory calibration, "
        "%.3f px refined)",
        report->rms_before_px,
        report->rms_after_px);
  }
  return "";
}

// Whether the factory calibration alone explains `problem`'s tracks (as triangulated through the
// factory lenses) to within the keypoints' own noise: the RMS over the observations within
// outlier_error_px at most factory_fits_rms_px. Then no adjustment could lower it by
// min_rms_gain_px: the report is filled as for a kept factory calibration and the reason returned;
// otherwise "".
std::string FactoryFitsReason(const BaProblem& problem,
                              const RigRefinementOptions& options,
                              RigRefinementReport* report) {
  if (options.factory_fits_rms_px <= 0) return "";
  double sum = 0;
  int within = 0;
  for (const double error : ReprojectionErrors(problem)) {
    if (!(error <= options.outlier_error_px)) continue;
    sum += error * error;
    ++within;
  }
  const double rms_px = within > 0 ? std::sqrt(sum / within) : std::numeric_limits<double>::infinity();
  if (!(rms_px <= options.factory_fits_rms_px)) return "";
  report->factory_fits = true;
  report->rms_before_px = report->rms_after_px = rms_px;
  report->num_tracks = static_cast<int>(problem.points.size());
  report->num_observations = within;
  const int n = static_cast<int>(report->views.size());
  const std::vector<int> observations = ObservationsPerView(problem, n);
  for (int v = 0; v < n; ++v) report->views[v].observations = observations[v];
  AddHoldWarnings(report);
  return Format(
      "the factory calibration already fits the shot (reprojection RMS %.3f px, within the keypoints' "
      "noise of %.2f px: not adjusted)",
      rms_px,
      options.factory_fits_rms_px);
}

}  // namespace

StatusOr<RigRefinementResult> RefineRigCalibration(const std::vector<cv::Mat>& upright_tiles,
                                                   const RigCalibration& factory,
                                                   const RigRefinementOptions& options) {
  const StageClock::time_point start = StageClock::now();
  PX_RETURN_IF_ERROR(options.Validate());
  PX_RETURN_IF_ERROR(factory.Validate().WithContext("rig refinement: factory calibration"));
  PX_RETURN_IF_ERROR(CheckTiles(upright_tiles, factory));
  const int n = factory.NumViews();
  RigRefinementResult result;
  result.rig = factory;
  RigRefinementReport& report = result.report;
  const auto finish = [&](std::string reason) -> StatusOr<RigRefinementResult> {
    report.fallback_reason = std::move(reason);
    report.refined = report.fallback_reason.empty();
    if (!report.refined) result.rig = factory;
    report.total_ms = MsSince(start);
    return result;
  };
  report.views.resize(n);
  for (int i = 0; i < n; ++i) report.views[i].view = i;
  if (!options.enabled) return finish("per-shot refinement is disabled");
  if (n < 2) return finish("a rig of one lens has nothing to refine against");

  // 1. Features, and their rays through the factory lenses.
  StageClock::time_point step = StageClock::now();
  PX_ASSIGN_OR_RETURN(std::vector<Features> features, DetectFeaturesInImages(upright_tiles, options.features));
  const std::vector<ViewData> views =
      ViewsThroughFactoryLenses(std::move(features), upright_tiles, factory, &report.views);
  const int usable_views = CountUsable(views);
  report.features_ms = MsSince(step);
  if (usable_views < 2) return finish(TooFewFeaturesReason(views, usable_views, upright_tiles));

  // 2. Nearby lens pairs, matched and verified in parallel (each with its own seed).
  step = StageClock::now();
  const double spacing = SmallestSpacing(factory);
  const std::vector<std::pair<int, int>> pair_list = NearbyPairs(views, factory, spacing, options);
  const RansacOptions ransac = RigRansac(factory, options);
  PairMatching matching = MatchNearbyPairs(views, pair_list, factory, ransac, options);
  report.pairs = std::move(matching.figures);
  SummarisePairs(options, &report);

  // 3. Tracks, triangulated with the factory calibration.
  BaProblem problem = TriangulateWithFactory(views, matching.verified, factory, options);

  // 4. P3P per view against those points; views left with too few observations are held.
  KeepP3pInliers(factory, ransac, options, &problem);
  const HeldViews held_views = HoldSparseViews(upright_tiles, options, &problem, &report.views);
  report.matching_ms = MsSince(step);
  if (held_views.refinable < 2 || static_cast<int>(problem.points.size()) < options.min_tracks) {
    return finish(TooFewMatchesReason(problem, held_views.refinable, options, report));
  }

  // 5. Nothing to refine when the factory calibration already explains the matches.
  step = StageClock::now();
  if (std::string fits = FactoryFitsReason(problem, options, &report); !fits.empty()) {
    report.adjustment_ms = MsSince(step);
    return finish(std::move(fits));
  }

  // 6. Bundle adjustment with the factory calibration as the prior, twice (outliers dropped).
  const std::vector<BaPrior> priors = FactoryPriors(factory, held_views.held, spacing, options);
  PX_ASSIGN_OR_RETURN(const AdjustmentPasses passes, AdjustTwice(priors, report.centres_held, options, &problem));
  report.adjustment_iterations = passes.first.iterations + passes.second.iterations;
  report.num_tracks = static_cast<int>(problem.points.size());
  report.num_observations = static_cast<int>(problem.observations.size());
  report.rms_after_px = passes.second.final_rms_px;
  PX_ASSIGN_OR_RETURN(report.rms_before_px, FactoryRms(problem, factory, options.num_threads));
  report.adjustment_ms = MsSince(step);

  // 7. Trust: what moved, and whether it helped.
  RefinedRig refined =
      CompareWithFactory(factory, problem, held_views.held, ObservationsPerView(problem, n), spacing, options, &report);
  AddHoldWarnings(&report);
  const std::string fallback = FallbackReason(passes.second.message, refined.implausible, options, &report);
  if (fallback.empty()) result.rig = std::move(refined.rig);
  return finish(fallback);
}

}  // namespace px::calib
