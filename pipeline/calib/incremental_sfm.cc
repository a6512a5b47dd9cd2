#include "pipeline/calib/incremental_sfm.h"

#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>
#include <optional>

#include "pipeline/calib/absolute_pose.h"
#include "pipeline/calib/bundle_adjustment.h"
#include "pipeline/calib/relative_pose.h"
#include "pipeline/calib/tracks.h"
#include "pipeline/calib/triangulation.h"
#include "pipeline/core/order_statistics.h"
#include "pipeline/core/stage_clock.h"

namespace px::calib {
namespace {

// A start for a focal length the sweep cannot find, over the image's longer side: 53 degrees
// across it, a 36 mm equivalent on 3:2 and 35 mm on 4:3, between a phone's 26 mm main camera and
// a 50 mm normal lens.
constexpr double kNormalLensRatio = 1.0;

// Features below this make an image useless for matching.
constexpr int kMinFeatures = 30;
// Triangulated points must be seen at least this far apart (degrees): below, their depth is
// noise. Small on purpose: 3 cm at 3 m is 0.57 degrees.
constexpr double kMinTriangulationAngleDeg = 0.05;
// Views already within this of parallel (degrees) gain nothing from a parallel restart.
constexpr double kMinRotationForParallelRestartDeg = 0.25;
// The restart's reconstruction is built beside the main one when the initial pair turns by less
// than this many times the restart's rotation limit (the finished views rarely turn much more).
constexpr double kSpeculativeRestartFactor = 2.0;
// A homography that explains a pair's matches to within this many times their epipolar noise
// means a plane or a scene at infinity (pure noise gives ~1.3).
constexpr double kPlanarHomographyRatio = 3.0;

template <typename... Args>
std::string Printf(const char* format, Args... args) {
  char text[400];
  std::snprintf(text, sizeof(text), format, args...);
  return text;
}

bool SameIntrinsics(const CameraModel& a, const CameraModel& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy && a.cx == b.cx && a.cy == b.cy &&
         a.distortion == b.distortion;
}

struct ImageState {
  Features features;
  CameraModel camera;  // current intrinsics (input-image pixels)
  bool known_intrinsics = false;
  int group = -1;          // shared intrinsics block, -1 = own
  double pixel_scale = 1;  // input-image pixels per feature-image pixel (>= 1)
  bool registered = false;
  Rigid3 cam_from_world;
  std::vector<int> track_of_feature;
  std::string note;
};

class Reconstruction {
 public:
  Reconstruction(std::vector<ImageState> images, std::vector<Track> tracks, const SfmOptions& options)
      : images_(std::move(images)),
        tracks_(std::move(tracks)),
        options_(options),
        point_of_track_(tracks_.size(), -1),
        rejected_(tracks_.size()) {
    for (size_t t = 0; t < tracks_.size(); ++t) {
      rejected_[t].assign(tracks_[t].observations.size(), 0);
      for (const TrackObservation& o : tracks_[t].observations) {
        images_[o.view].track_of_feature[o.feature] = static_cast<int>(t);
      }
    }
  }

  std::vector<ImageState>& images() { return images_; }
  const std::vector<ImageState>& images() const { return images_; }
  const std::vector<Eigen::Vector3d>& points() const { return points_; }
  int NumRegistered() const {
    int n = 0;
    for (const ImageState& image : images_) n += image.registered ? 1 : 0;
    return n;
  }
  // Largest rotation between two registered images, degrees.
  double MaxRotationDeg() const {
    double max_deg = 0;
    for (size_t i = 0; i < images_.size(); ++i) {
      for (size_t j = i + 1; j < images_.size(); ++j) {
        if (!images_[i].registered || !images_[j].registered) continue;
        max_deg = std::max(max_deg, RotationErrorDeg(images_[j].cam_from_world, images_[i].cam_from_world));
      }
    }
    return max_deg;
  }
  // Focal lengths are worth refining unless every registered image has one from metadata and
  // the views are not rotated: then the images cannot improve on it (focal length and depth
  // scale are one ambiguity) and a free focal length would only drift with model errors.
  bool FocalRefinable(double min_rotation_deg) const {
    bool all_known = true;
    for (const ImageState& image : images_) all_known &= !image.registered || image.known_intrinsics;
    return !all_known || MaxRotationDeg() >= min_rotation_deg;
  }
  // Error threshold in an image's input pixels.
  double Threshold(int image, double feature_px) const { return feature_px * images_[image].pixel_scale; }

  Eigen::Vector3d Ray(int image, int feature) const {
    return images_[image].camera.Unproject(images_[image].features.keypoints_px[feature]);
  }

  // Triangulates every track with two or more registered, unrejected observations and no
  // point yet; keeps points in front of all their views, within the threshold, seen at an angle.
  int TriangulateNewTracks() {
    int added = 0;
    for (size_t t = 0; t < tracks_.size(); ++t) {
      if (point_of_track_[t] >= 0) continue;
      std::vector<Rigid3> poses;
      std::vector<Eigen::Vector3d> rays;
      std::vector<int> used;
      for (size_t k = 0; k < tracks_[t].observations.size(); ++k) {
        const TrackObservation& o = tracks_[t].observations[k];
        if (!images_[o.view].registered || rejected_[t][k]) continue;
        poses.push_back(images_[o.view].cam_from_world);
        rays.push_back(Ray(o.view, o.feature));
        used.push_back(static_cast<int>(k));
      }
      if (poses.size() < 2) continue;
      const std::optional<Eigen::Vector3d> point = TriangulatePoint(poses, rays);
      if (!point || MaxTriangulationAngleDeg(*point, poses) < kMinTriangulationAngleDeg) continue;
      bool good = true;
      for (int k : used) {
        const TrackObservation& o = tracks_[t].observations[k];
        Eigen::Vector2d projected;
        const ImageState& image = images_[o.view];
        if (!image.camera.Project(image.cam_from_world * *point, &projected) ||
            (projected - image.features.keypoints_px[o.feature]).norm() > Threshold(o.view, options_.max_error_px)) {
          good = false;
          break;
        }
      }
      if (!good) continue;
      point_of_track_[t] = static_cast<int>(points_.size());
      points_.push_back(*point);
      track_of_point_.push_back(static_cast<int>(t));
      ++added;
    }
    return added;
  }

  // 2D-3D correspondences of an unregistered image: rays and points of its tracks with points.
  void Correspondences(int image,
                       std::vector<Eigen::Vector3d>* rays,
                       std::vector<Eigen::Vector3d>* points,
                       std::vector<std::pair<int, int>>* track_and_index) const {
    for (size_t t = 0; t < tracks_.size(); ++t) {
      if (point_of_track_[t] < 0) continue;
      for (size_t k = 0; k < tracks_[t].observations.size(); ++k) {
        const TrackObservation& o = tracks_[t].observations[k];
        if (o.view != image) continue;
        rays->push_back(Ray(image, o.feature));
        points->push_back(points_[point_of_track_[t]]);
        track_and_index->emplace_back(static_cast<int>(t), static_cast<int>(k));
      }
    }
  }

  void Reject(int track, int index) { rejected_[track][index] = 1; }

  // Bundle adjustment of every registered image and every point. `anchor` is held (the gauge)
  // and its distance to `second` fixes the scale.
  StatusOr<BundleAdjustmentReport> Adjust(
      int anchor, int second, bool refine_focal, bool refine_radial, int max_iterations) {
    BaProblem problem;
    std::vector<int> camera_of_image(images_.size(), -1);
    std::vector<int> image_of_camera;
    for (size_t i = 0; i < images_.size(); ++i) {
      if (!images_[i].registered) continue;
      camera_of_image[i] = static_cast<int>(problem.cameras.size());
      image_of_camera.push_back(static_cast<int>(i));
      BaCamera camera;
      camera.camera = images_[i].camera;
      camera.cam_from_world = images_[i].cam_from_world;
      camera.intrinsics_group = images_[i].group;
      camera.pose_fixed = static_cast<int>(i) == anchor;
      problem.cameras.push_back(camera);
    }
    std::vector<std::pair<int, int>> observation_source;  // (track, index)
    std::vector<int> point_index(points_.size(), -1);
    for (size_t t = 0; t < tracks_.size(); ++t) {
      if (point_of_track_[t] < 0) continue;
      for (size_t k = 0; k < tracks_[t].observations.size(); ++k) {
        const TrackObservation& o = tracks_[t].observations[k];
        if (camera_of_image[o.view] < 0 || rejected_[t][k]) continue;
        int& p = point_index[point_of_track_[t]];
        if (p < 0) {
          p = static_cast<int>(problem.points.size());
          problem.points.push_back(points_[point_of_track_[t]]);
        }
        problem.observations.push_back({camera_of_image[o.view], p, images_[o.view].features.keypoints_px[o.feature]});
        observation_source.emplace_back(static_cast<int>(t), static_cast<int>(k));
      }
    }
    std::vector<BaPrior> priors;
    std::vector<char> group_has_prior(images_.size() + 1, 0);
    for (size_t c = 0; c < problem.cameras.size(); ++c) {
      const ImageState& image = images_[image_of_camera[c]];
      if (!image.known_intrinsics) continue;
      if (image.group >= 0) {
        if (group_has_prior[image.group]) continue;
        group_has_prior[image.group] = 1;
      }
      BaPrior prior;
      prior.camera = static_cast<int>(c);
      prior.focal_px = image.camera.fx;
      prior.focal_sigma_relative = options_.metadata_focal_sigma_relative;
      prior.cx = image.camera.cx;
      prior.cy = image.camera.cy;
      priors.push_back(prior);
    }
    BundleAdjustmentOptions ba;
    ba.refine_focal = refine_focal;
    ba.refine_radial = refine_radial;
    ba.loss_scale_px = options_.loss_scale_px * images_[anchor].pixel_scale;
    ba.num_threads = options_.num_threads;
    ba.max_iterations = max_iterations;
    ba.scale_anchor_a = camera_of_image[anchor];
    ba.scale_anchor_b = second >= 0 && camera_of_image[second] >= 0 ? camera_of_image[second] : -1;
    PX_ASSIGN_OR_RETURN(BundleAdjustmentReport report, BundleAdjust(&problem, priors, ba));
    for (size_t c = 0; c < problem.cameras.size(); ++c) {
      ImageState& image = images_[image_of_camera[c]];
      image.camera = problem.cameras[c].camera;
      image.cam_from_world = problem.cameras[c].cam_from_world;
      // Images not registered yet share their group's refined intrinsics too.
      for (ImageState& other : images_) {
        if (image.group >= 0 && other.group == image.group) other.camera = image.camera;
      }
    }
    for (size_t p = 0; p < points_.size(); ++p) {
      if (point_index[p] >= 0) points_[p] = problem.points[point_index[p]];
    }
    // Reject observations beyond the outlier threshold; points left with fewer than two go.
    const std::vector<double> errors = ReprojectionErrors(problem);
    for (size_t i = 0; i < errors.size(); ++i) {
      const auto [t, k] = observation_source[i];
      const int image = tracks_[t].observations[k].view;
      if (!(errors[i] <= Threshold(image, options_.outlier_error_px))) rejected_[t][k] = 1;
    }
    DropWeakPoints();
    return report;
  }

  // Observations (image, point, pixel) of the current reconstruction.
  template <typename Visit>
  void ForEachObservation(Visit visit) const {
    for (size_t t = 0; t < tracks_.size(); ++t) {
      if (point_of_track_[t] < 0) continue;
      for (size_t k = 0; k < tracks_[t].observations.size(); ++k) {
        const TrackObservation& o = tracks_[t].observations[k];
        if (!images_[o.view].registered || rejected_[t][k]) continue;
        visit(o.view, point_of_track_[t], images_[o.view].features.keypoints_px[o.feature]);
      }
    }
  }

  // Reprojection RMS (input-image pixels) and count of the current observations.
  double Rms(int* count) const {
    double sum_squares = 0;
    *count = 0;
    ForEachObservation([&](int image, int point, const Eigen::Vector2d& pixel) {
      Eigen::Vector2d projected;
      if (images_[image].camera.Project(images_[image].cam_from_world * points_[point], &projected)) {
        sum_squares += (projected - pixel).squaredNorm();
        ++*count;
      }
    });
    return *count > 0 ? std::sqrt(sum_squares / *count) : 0.0;
  }

  // Moves the world to `anchor`'s camera frame, scaled by `scale`.
  void Transform(int anchor, double scale) {
    const Rigid3 anchor_from_world = images_[anchor].cam_from_world;
    const Rigid3 world_from_anchor = anchor_from_world.Inverse();
    for (ImageState& image : images_) {
      if (!image.registered) continue;
      Rigid3 pose = image.cam_from_world * world_from_anchor;
      pose.translation *= scale;
      image.cam_from_world = pose;
    }
    for (Eigen::Vector3d& point : points_) point = scale * (anchor_from_world * point);
  }

 private:
  void DropWeakPoints() {
    for (size_t t = 0; t < tracks_.size(); ++t) {
      if (point_of_track_[t] < 0) continue;
      int active = 0;
      for (size_t k = 0; k < tracks_[t].observations.size(); ++k) {
        active += images_[tracks_[t].observations[k].view].registered && !rejected_[t][k] ? 1 : 0;
      }
      if (active < 2) point_of_track_[t] = -1;  // the point's slot stays; it is no longer used
    }
  }

  std::vector<ImageState> images_;
  std::vector<Track> tracks_;
  SfmOptions options_;
  std::vector<int> point_of_track_;
  std::vector<std::vector<char>> rejected_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<int> track_of_point_;
};

// 1. Features of every image. An empty or non-8-bit image, or intrinsics for another size, is an error.
StatusOr<std::vector<Features>> DetectImageFeatures(const std::vector<SfmImage>& input, const SfmOptions& options) {
  const int n = static_cast<int>(input.size());
  std::vector<cv::Mat> pixels;
  for (int i = 0; i < n; ++i) {
    if (input[i].image.empty() || input[i].image.depth() != CV_8U) {
      return InvalidArgumentError("structure from motion: image " + std::to_string(i) + " is empty or not 8-bit");
    }
    if (input[i].intrinsics.fx != 0) {
      PX_RETURN_IF_ERROR(input[i].intrinsics.Validate().WithContext("structure from motion: image " +
                                                                    std::to_string(i) + " intrinsics"));
      if (input[i].intrinsics.width != input[i].image.cols || input[i].intrinsics.height != input[i].image.rows) {
        return InvalidArgumentError("structure from motion: image " + std::to_string(i) + " is " +
                                    std::to_string(input[i].image.cols) + "x" + std::to_string(input[i].image.rows) +
                                    ", its intrinsics are for " + std::to_string(input[i].intrinsics.width) + "x" +
                                    std::to_string(input[i].intrinsics.height));
      }
    }
    pixels.push_back(input[i].image);
  }
  return DetectFeaturesInImages(pixels, options.features);
}

// The images before matching: intrinsics from metadata, or a starting focal length that the sweep replaces;
// an image with too few features to match is noted (with what its exposure suggests) and left out.
std::vector<ImageState> StartImages(const std::vector<SfmImage>& input,
                                    std::vector<Features> features,
                                    const SfmOptions& options) {
  const int n = static_cast<int>(input.size());
  std::vector<ImageState> images(n);
  for (int i = 0; i < n; ++i) {
    ImageState& image = images[i];
    image.features = std::move(features[i]);
    image.track_of_feature.assign(image.features.size(), -1);
    const int larger = std::max(input[i].image.cols, input[i].image.rows);
    image.pixel_scale = std::max(1.0, static_cast<double>(larger) / options.features.max_image_dim_px);
    image.known_intrinsics = input[i].intrinsics.fx != 0;
    image.camera = image.known_intrinsics
                       ? input[i].intrinsics
                       : CameraModel::Pinhole(input[i].image.cols, input[i].image.rows, 1.2 * larger);
    if (image.features.size() < kMinFeatures) {
      image.note = std::to_string(image.features.size()) + " features: the image is " +
                   DescribeFewFeatures(MeasureExposure(input[i].image));
    }
  }
  return images;
}

// Intrinsics blocks of the adjustment: unknown intrinsics are shared per camera id, known ones when identical;
// an image alone in its block has its own.
void GroupIntrinsics(const std::vector<SfmImage>& input, std::vector<ImageState>* images_ptr) {
  std::vector<ImageState>& images = *images_ptr;
  const int n = static_cast<int>(input.size());
  std::map<std::pair<int, bool>, int> group_of;
  for (int i = 0; i < n; ++i) {
    const auto key = std::make_pair(input[i].camera_id, images[i].known_intrinsics);
    auto found = group_of.find(key);
    if (found == group_of.end()) {
      group_of[key] = i;
      images[i].group = i;
    } else if (SameIntrinsics(images[found->second].camera, images[i].camera)) {
      images[i].group = found->second;
    } else {
      images[i].group = -1;
    }
  }
  for (int i = 0; i < n; ++i) {
    bool shared = false;
    for (int j = 0; j < n; ++j) shared |= j != i && images[j].group == images[i].group && images[i].group >= 0;
    if (!shared) images[i].group = -1;
  }
}

// Whether some image has no focal length from metadata: then one is swept.
bool AnyUnknownIntrinsics(const std::vector<ImageState>& images) {
  bool any_unknown = false;
  for (const ImageState& image : images) any_unknown |= !image.known_intrinsics;
  return any_unknown;
}

// Fundamental-matrix verification of a pair's matches (any focal length).
std::vector<FeatureMatch> VerifyWithFundamental(const Features& a,
                                                const Features& b,
                                                const std::vector<FeatureMatch>& matches,
                                                double threshold_px) {
  std::vector<FeatureMatch> verified;
  if (matches.size() < 8) return verified;
  std::vector<cv::Point2d> pa, pb;
  for (const FeatureMatch& m : matches) {
    pa.emplace_back(a.keypoints_px[m.a].x(), a.keypoints_px[m.a].y());
    pb.emplace_back(b.keypoints_px[m.b].x(), b.keypoints_px[m.b].y());
  }
  std::vector<uchar> mask;
  const cv::Mat f = cv::findFundamentalMat(pa, pb, cv::FM_RANSAC, threshold_px, 0.999, mask);
  if (f.empty() || mask.size() != matches.size()) return verified;
  for (size_t i = 0; i < matches.size(); ++i) {
    if (mask[i]) verified.push_back(matches[i]);
  }
  return verified;
}

// What matching all pairs found: each pair's verified matches, and its figures for the report.
struct PairMatching {
  std::vector<PairMatches> verified;
  std::vector<SfmPair> figures;
};

// 2. Ratio + mutual matches of every pair of images with enough features, verified by a fundamental matrix;
// in parallel, each pair writing only its own slot.
PairMatching MatchAllPairs(const std::vector<ImageState>& images, const SfmOptions& options) {
  const int n = static_cast<int>(images.size());
  std::vector<std::pair<int, int>> pair_list;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      if (images[i].note.empty() && images[j].note.empty()) pair_list.emplace_back(i, j);
    }
  }
  PairMatching matching;
  matching.verified.resize(pair_list.size());
  matching.figures.resize(pair_list.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(pair_list.size())), [&](const cv::Range& range) {
    for (int p = range.start; p < range.end; ++p) {
      const auto [a, b] = pair_list[p];
      const std::vector<FeatureMatch> matches = MatchAll(images[a].features, images[b].features, options.matching);
      const double threshold = options.max_error_px * std::max(images[a].pixel_scale, images[b].pixel_scale);
      matching.verified[p] = {a, b, VerifyWithFundamental(images[a].features, images[b].features, matches, threshold)};
      matching.figures[p] = {
          a, b, static_cast<int>(matches.size()), static_cast<int>(matching.verified[p].matches.size())};
    }
  });
  return matching;
}

// The pairs with enough verified matches to build tracks on and to start from.
std::vector<PairMatches> UsablePairs(const std::vector<PairMatches>& verified, const SfmOptions& options) {
  std::vector<PairMatches> usable_pairs;
  for (const PairMatches& pair : verified) {
    if (static_cast<int>(pair.matches.size()) >= options.min_pair_matches) usable_pairs.push_back(pair);
  }
  return usable_pairs;
}

// Notes each image that no pair verifies well enough, with what its exposure suggests is wrong: it is not
// registered.
void NoteUnmatchedImages(const std::vector<SfmImage>& input,
                         const std::vector<PairMatches>& verified,
                         const SfmOptions& options,
                         std::vector<ImageState>* images_ptr) {
  std::vector<ImageState>& images = *images_ptr;
  const int n = static_cast<int>(input.size());
  for (int i = 0; i < n; ++i) {
    if (!images[i].note.empty()) continue;
    int best = 0;
    for (const PairMatches& pair : verified) {
      if (pair.view_a == i || pair.view_b == i) best = std::max(best, static_cast<int>(pair.matches.size()));
    }
    if (best < options.min_pair_matches) {
      const std::string exposure = DescribeExposureProblem(MeasureExposure(input[i].image));
      images[i].note = "matches no other image (at most " + std::to_string(best) + " verified matches, need " +
                       std::to_string(options.min_pair_matches) +
                       "): " + (exposure.empty() ? "a different scene?" : "the image is " + exposure);
    }
  }
}

// Tracks through the pairs' matches.
std::vector<Track> TracksOfPairs(const std::vector<ImageState>& images, const std::vector<PairMatches>& pairs) {
  std::vector<int> feature_counts;
  for (const ImageState& image : images) feature_counts.push_back(image.features.size());
  return BuildTracks(feature_counts, pairs);
}

// Why no pair is usable: too few images with features, or images that share too little.
std::string NoUsablePairReason(const std::vector<SfmImage>& input,
                               const std::vector<ImageState>& images,
                               const SfmOptions& options) {
  const int n = static_cast<int>(input.size());
  int usable = 0;
  for (const ImageState& image : images) usable += image.features.size() >= kMinFeatures ? 1 : 0;
  if (usable < 2) {
    return "too few features: " + std::to_string(usable) + " of " + std::to_string(n) + " images have " +
           std::to_string(kMinFeatures) + " or more (image 0 is " +
           DescribeFewFeatures(MeasureExposure(input[0].image)) + ")";
  }
  return "no two images share enough features (" + std::to_string(options.min_pair_matches) +
         " verified matches needed): do they show the same scene?";
}

struct PairGeometry {
  int pair = -1;
  RelativePoseResult pose;
  double parallax_ratio = 0;
};

// Five-point pose of a verified pair with the images' current intrinsics.
PairGeometry PairPose(const std::vector<ImageState>& images,
                      const PairMatches& pair,
                      int index,
                      const SfmOptions& options) {
  PairGeometry geometry;
  geometry.pair = index;
  std::vector<Eigen::Vector3d> rays_a, rays_b;
  const ImageState& a = images[pair.view_a];
  const ImageState& b = images[pair.view_b];
  for (const FeatureMatch& m : pair.matches) {
    rays_a.push_back(a.camera.Unproject(a.features.keypoints_px[m.a]));
    rays_b.push_back(b.camera.Unproject(b.features.keypoints_px[m.b]));
  }
  RansacOptions ransac = options.ransac;
  ransac.focal_px = 0.5 * (a.camera.fx / a.pixel_scale + b.camera.fx / b.pixel_scale);
  ransac.max_error_px = options.max_error_px;
  ransac.seed = options.ransac.seed * 7919ULL + static_cast<uint64_t>(index);
  geometry.pose = EstimateRelativePose(rays_a, rays_b, RelativePoseSolver::kFivePoint, ransac);
  if (geometry.pose.success) geometry.parallax_ratio = geometry.pose.ParallaxRatio();
  return geometry;
}

// Starts a reconstruction from a pair: first image at the origin, second at b_from_a (unit
// baseline), points triangulated, two-view adjustment with the focal length held.
StatusOr<BundleAdjustmentReport> InitialisePair(Reconstruction* reconstruction,
                                                const PairMatches& pair,
                                                const RelativePoseResult& pose) {
  std::vector<ImageState>& images = reconstruction->images();
  images[pair.view_a].registered = true;
  images[pair.view_a].cam_from_world = Rigid3();
  images[pair.view_b].registered = true;
  images[pair.view_b].cam_from_world = pose.b_from_a;
  if (reconstruction->TriangulateNewTracks() < 8) {
    return FailedPreconditionError("fewer than 8 points triangulate between images " + std::to_string(pair.view_a) +
                                   " and " + std::to_string(pair.view_b));
  }
  return reconstruction->Adjust(pair.view_a, pair.view_b, /*refine_focal=*/false, /*refine_radial=*/false, 50);
}

// 3. Self-calibration: sweeps the focal length of the images without one on the pair with the most verified
// matches, scoring each step by the pair's two-view adjustment, and sets the best. Returns the sweep's
// (focal px of the pair's first image, two-view RMS px) per step, for the report.
std::vector<std::pair<double, double>> SweepFocalLength(const std::vector<PairMatches>& usable_pairs,
                                                        const std::vector<Track>& tracks,
                                                        const SfmOptions& options,
                                                        std::vector<ImageState>* images_ptr) {
  std::vector<ImageState>& images = *images_ptr;
  const int n = static_cast<int>(images.size());
  std::vector<std::pair<double, double>> sweep;
  const PairMatches* sweep_pair = &usable_pairs[0];
  for (const PairMatches& pair : usable_pairs) {
    if (pair.matches.size() > sweep_pair->matches.size()) sweep_pair = &pair;
  }
  const auto ratio_of_step = [&](int k) {
    return options.focal_sweep_min * std::pow(options.focal_sweep_max / options.focal_sweep_min,
                                              static_cast<double>(k) / (options.focal_sweep_steps - 1));
  };
  // The steps are independent (each seeded alike, its adjustment on SfmOptions::num_threads, 1 by
  // default), so they run side by side on every core and give the same figures as one after another.
  std::vector<double> step_rms(options.focal_sweep_steps, std::numeric_limits<double>::infinity());
  cv::parallel_for_(cv::Range(0, options.focal_sweep_steps), [&](const cv::Range& range) {
    for (int k = range.start; k < range.end; ++k) {
      const double ratio = ratio_of_step(k);
      std::vector<ImageState> trial = images;
      for (int i = 0; i < n; ++i) {
        if (trial[i].known_intrinsics) continue;
        trial[i].camera.fx = trial[i].camera.fy = ratio * std::max(trial[i].camera.width, trial[i].camera.height);
      }
      const PairGeometry geometry = PairPose(trial, *sweep_pair, 0, options);
      if (!geometry.pose.success) continue;
      Reconstruction two_view(trial, tracks, options);
      StatusOr<BundleAdjustmentReport> adjusted = InitialisePair(&two_view, *sweep_pair, geometry.pose);
      if (adjusted.ok()) step_rms[k] = adjusted->final_rms_px;
    }
  });
  double best_rms = std::numeric_limits<double>::infinity();
  double best_ratio = 1.2;
  for (int k = 0; k < options.focal_sweep_steps; ++k) {
    const double ratio = ratio_of_step(k);
    sweep.emplace_back(
        ratio * std::max(images[sweep_pair->view_a].camera.width, images[sweep_pair->view_a].camera.height),
        step_rms[k]);
    if (step_rms[k] < best_rms) {
      best_rms = step_rms[k];
      best_ratio = ratio;
    }
  }
  // A best at either end of the range is no minimum: the pair's residual falls on towards the
  // end (a nearly translated pair fits a longer focal ever better; the simulated still life's
  // went from 0.24 px at the true 0.875 to 0.16 at 2.5, and the set was built at 2.2 times the
  // true focal). Then start from a normal lens and let the adjustment with every view move it.
  if (best_ratio == options.focal_sweep_min || best_ratio == options.focal_sweep_max) best_ratio = kNormalLensRatio;
  for (ImageState& image : images) {
    if (!image.known_intrinsics) {
      image.camera.fx = image.camera.fy = best_ratio * std::max(image.camera.width, image.camera.height);
    }
  }
  return sweep;
}

// The initial pair, if any, and the pair with the most parallax (to say why none was chosen).
struct InitialPairChoice {
  std::optional<PairGeometry> initial;
  std::optional<PairGeometry> most_parallax;  // among the pairs with a pose
};

// 4. Five-point poses of every usable pair (in parallel); the initial pair has enough parallax, then the most
// matches weighted by parallax up to the target.
InitialPairChoice ChooseInitialPair(const std::vector<ImageState>& images,
                                    const std::vector<PairMatches>& usable_pairs,
                                    const SfmOptions& options) {
  std::vector<PairGeometry> candidates(usable_pairs.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(usable_pairs.size())), [&](const cv::Range& range) {
    for (int p = range.start; p < range.end; ++p) candidates[p] = PairPose(images, usable_pairs[p], p, options);
  });
  const PairGeometry* initial = nullptr;
  double best_score = 0;
  const PairGeometry* most_parallax = nullptr;
  for (const PairGeometry& candidate : candidates) {
    if (!candidate.pose.success) continue;
    if (most_parallax == nullptr || candidate.parallax_ratio > most_parallax->parallax_ratio)
      most_parallax = &candidate;
    if (candidate.parallax_ratio < options.min_parallax_ratio) continue;
    const double score = static_cast<double>(candidate.pose.inliers.size()) *
                         std::min(1.0, candidate.pose.median_parallax_px / options.target_parallax_px);
    if (score > best_score) {
      best_score = score;
      initial = &candidate;
    }
  }
  InitialPairChoice choice;
  if (initial != nullptr) choice.initial = *initial;
  if (most_parallax != nullptr) choice.most_parallax = *most_parallax;
  return choice;
}

// Why no pair can start the reconstruction: no consistent relative pose, or no parallax.
std::string NoInitialPairReason(const InitialPairChoice& choice,
                                const std::vector<PairMatches>& usable_pairs,
                                const SfmOptions& options) {
  if (!choice.most_parallax) return "no pair of images has a consistent relative pose";
  const PairGeometry& most_parallax = *choice.most_parallax;
  const PairMatches& pair = usable_pairs[most_parallax.pair];
  return Printf(
      "no parallax: the camera only rotated, or the scene is too far for the baseline (best pair, "
      "images %.0f and %.0f: parallax %.2f px, %.1f times the matching noise; need %.1f). Depth "
      "cannot be recovered; move the camera sideways between shots",
      static_cast<double>(pair.view_a),
      static_cast<double>(pair.view_b),
      most_parallax.pose.median_parallax_px,
      most_parallax.parallax_ratio,
      options.min_parallax_ratio);
}

// Records the initial pair and its parallax figures in the report.
void RecordInitialPair(const PairGeometry& initial, const PairMatches& pair, SfmReport* report) {
  report->initial_image_a = pair.view_a;
  report->initial_image_b = pair.view_b;
  report->initial_parallax_px = initial.pose.median_parallax_px;
  report->initial_parallax_ratio = initial.parallax_ratio;
  report->initial_homography_ratio = initial.pose.HomographyRatio();
}

// 5-6. Registers the rest of the images, best connected first (P3P), triangulating and adjusting
// after each; then the final adjustment, focal lengths (and distortion when asked) with every view.
Status RegisterAndAdjust(Reconstruction* reconstruction_ptr, int anchor, int second, const SfmOptions& options) {
  Reconstruction& reconstruction = *reconstruction_ptr;
  const int n = static_cast<int>(reconstruction.images().size());
  std::vector<char> failed(n, 0);
  while (true) {
    int best_image = -1;
    size_t best_count = 0;
    for (int i = 0; i < n; ++i) {
      if (reconstruction.images()[i].registered || failed[i] || !reconstruction.images()[i].note.empty()) continue;
      std::vector<Eigen::Vector3d> rays, points;
      std::vector<std::pair<int, int>> sources;
      reconstruction.Correspondences(i, &rays, &points, &sources);
      if (rays.size() > best_count) {
        best_count = rays.size();
        best_image = i;
      }
    }
    if (best_image < 0) break;
    std::vector<Eigen::Vector3d> rays, points;
    std::vector<std::pair<int, int>> sources;
    reconstruction.Correspondences(best_image, &rays, &points, &sources);
    ImageState& image = reconstruction.images()[best_image];
    RansacOptions ransac = options.ransac;
    ransac.focal_px = image.camera.fx / image.pixel_scale;
    ransac.max_error_px = options.max_error_px;
    ransac.seed = options.ransac.seed * 104729ULL + static_cast<uint64_t>(best_image);
    const AbsolutePoseResult pose = EstimateAbsolutePose(rays, points, AbsolutePoseSolver::kP3p, ransac);
    if (!pose.success || static_cast<int>(pose.inliers.size()) < options.min_registration_inliers) {
      failed[best_image] = 1;
      image.note = "P3P found " + std::to_string(pose.success ? pose.inliers.size() : 0) + " inliers among " +
                   std::to_string(rays.size()) + " 2D-3D matches (need " +
                   std::to_string(options.min_registration_inliers) + ")";
      continue;
    }
    std::vector<char> inlier(rays.size(), 0);
    for (int i : pose.inliers) inlier[i] = 1;
    for (size_t i = 0; i < sources.size(); ++i) {
      if (!inlier[i]) reconstruction.Reject(sources[i].first, sources[i].second);
    }
    image.registered = true;
    image.cam_from_world = pose.cam_from_world;
    reconstruction.TriangulateNewTracks();
    const bool refine_focal =
        reconstruction.NumRegistered() >= 3 && reconstruction.FocalRefinable(options.min_rotation_for_focal_deg);
    PX_ASSIGN_OR_RETURN(BundleAdjustmentReport adjusted,
                        reconstruction.Adjust(anchor, second, refine_focal, false, 50));
    (void)adjusted;
    reconstruction.TriangulateNewTracks();
  }

  // 6. Final adjustment, twice (the first one's outliers are dropped before the second).
  const bool refine_focal = reconstruction.FocalRefinable(options.min_rotation_for_focal_deg);
  for (int pass = 0; pass < 2; ++pass) {
    PX_RETURN_IF_ERROR(
        reconstruction.Adjust(anchor, second, refine_focal, options.refine_radial_distortion, 100).status());
  }
  return OkStatus();
}

// The initial pair's pose if the cameras are parallel (rotation identity): the translation
// direction that best satisfies x_b . (t x x_a) = 0 over the five-point inliers, of the sign
// whose two-view adjustment fits better; the pair initialised from it, or nothing if it fails.
std::optional<Reconstruction> ParallelStart(const std::vector<ImageState>& images,
                                            const std::vector<Track>& tracks,
                                            const PairMatches& pair,
                                            const RelativePoseResult& pose,
                                            const SfmOptions& options) {
  Eigen::MatrixXd constraints(pose.inliers.size(), 3);
  for (size_t k = 0; k < pose.inliers.size(); ++k) {
    const FeatureMatch& m = pair.matches[pose.inliers[k]];
    const Eigen::Vector3d a = images[pair.view_a].camera.Unproject(images[pair.view_a].features.keypoints_px[m.a]);
    const Eigen::Vector3d b = images[pair.view_b].camera.Unproject(images[pair.view_b].features.keypoints_px[m.b]);
    constraints.row(k) = a.cross(b).normalized().transpose();
  }
  if (constraints.rows() < 8) return std::nullopt;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(constraints, Eigen::ComputeFullV);
  const Eigen::Vector3d direction = svd.matrixV().col(2);
  std::optional<Reconstruction> best;
  double best_rms = std::numeric_limits<double>::infinity();
  for (double sign : {1.0, -1.0}) {
    RelativePoseResult parallel = pose;
    parallel.b_from_a = Rigid3(Eigen::Quaterniond::Identity(), sign * direction);
    Reconstruction candidate(images, tracks, options);
    StatusOr<BundleAdjustmentReport> adjusted = InitialisePair(&candidate, pair, parallel);
    if (adjusted.ok() && adjusted->final_rms_px < best_rms) {
      best_rms = adjusted->final_rms_px;
      best = std::move(candidate);
    }
  }
  return best;
}

// What the parallel restart did: whether it replaced the reconstruction, and the two fits it compared.
struct ParallelRestartReport {
  bool rebuilt = false;
  double rms_px = 0;           // the five-point start's
  double parallel_rms_px = 0;  // the translation-only start's
};

// The restart's reconstruction: the rest registered and adjusted on the translation-only start,
// or nothing if that start fails.
using ParallelCandidate = StatusOr<std::optional<Reconstruction>>;
ParallelCandidate BuildParallelCandidate(const std::vector<ImageState>& images,
                                         const std::vector<Track>& tracks,
                                         const PairMatches& pair,
                                         const RelativePoseResult& pose,
                                         const SfmOptions& options) {
  std::optional<Reconstruction> parallel = ParallelStart(images, tracks, pair, pose, options);
  if (parallel) PX_RETURN_IF_ERROR(RegisterAndAdjust(&*parallel, pair.view_a, pair.view_b, options));
  return parallel;
}

// Parallel cameras (a lattice, a slider) with little parallax: the five-point pose can land in
// the wrong basin of the rotation / inverse-depth ambiguity (on the HCI grid 1.3 degrees off,
// at a worse RMS), so the set is rebuilt from the pair's translation-only pose and the better
// fit (an RMS at least 3 % lower) is kept. `built`: the candidate if it was built already
// (beside the main reconstruction), else empty.
StatusOr<ParallelRestartReport> RestartIfParallel(Reconstruction* reconstruction,
                                                  const std::vector<ImageState>& images,
                                                  const std::vector<Track>& tracks,
                                                  const PairMatches& pair,
                                                  const RelativePoseResult& pose,
                                                  const SfmOptions& options,
                                                  std::optional<ParallelCandidate>* built) {
  ParallelRestartReport restart;
  const double max_rotation_deg = reconstruction->MaxRotationDeg();
  if (!(max_rotation_deg >= kMinRotationForParallelRestartDeg &&
        max_rotation_deg < options.parallel_restart_max_rotation_deg)) {
    return restart;
  }
  ParallelCandidate candidate =
      built->has_value() ? std::move(**built) : BuildParallelCandidate(images, tracks, pair, pose, options);
  PX_RETURN_IF_ERROR(candidate.status());
  std::optional<Reconstruction>& parallel = *candidate;
  if (!parallel) return restart;
  int count = 0, parallel_count = 0;
  restart.rms_px = reconstruction->Rms(&count);
  restart.parallel_rms_px = parallel->Rms(&parallel_count);
  if (parallel->NumRegistered() >= reconstruction->NumRegistered() && parallel_count >= 0.95 * count &&
      restart.parallel_rms_px < 0.97 * restart.rms_px) {
    restart.rebuilt = true;
    *reconstruction = std::move(*parallel);
  }
  return restart;
}

// The warning of a rebuilt reconstruction: the two fits.
std::string ParallelRestartWarning(const ParallelRestartReport& restart) {
  return Printf(
      "rebuilt from a translation-only initial pair (parallel cameras): RMS %.3f px "
      "instead of %.3f px",
      restart.parallel_rms_px,
      restart.rms_px);
}

// 7. World = the first registered image's camera; scale = the points' median depth in their views, made
// options.median_depth.
void NormaliseWorld(Reconstruction* reconstruction, const SfmOptions& options) {
  const int n = static_cast<int>(reconstruction->images().size());
  int world_image = -1;
  for (int i = 0; i < n && world_image < 0; ++i) {
    if (reconstruction->images()[i].registered) world_image = i;
  }
  std::vector<double> depths;
  reconstruction->ForEachObservation([&](int image, int point, const Eigen::Vector2d&) {
    depths.push_back((reconstruction->images()[image].cam_from_world * reconstruction->points()[point]).z());
  });
  const double median = Percentile(depths, 0.5);
  reconstruction->Transform(world_image, median > 0 ? options.median_depth / median : 1.0);
}

// Figures over the final observations.
struct ObservationFigures {
  std::vector<std::vector<double>> view_depths;  // per image, of the points it observes
  int count = 0;                                 // observations that project
  double rms_px = 0;                             // their reprojection RMS, input-image pixels
};

// Each view's point depths (for its depth range) and the reprojection RMS of the final reconstruction.
ObservationFigures MeasureObservations(const Reconstruction& reconstruction) {
  ObservationFigures figures;
  figures.view_depths.resize(reconstruction.images().size());
  double sum_squares = 0;
  reconstruction.ForEachObservation([&](int image, int point, const Eigen::Vector2d& pixel) {
    const ImageState& state = reconstruction.images()[image];
    const Eigen::Vector3d p = state.cam_from_world * reconstruction.points()[point];
    figures.view_depths[image].push_back(p.z());
    Eigen::Vector2d projected;
    if (state.camera.Project(p, &projected)) {
      sum_squares += (projected - pixel).squaredNorm();
      ++figures.count;
    }
  });
  figures.rms_px = figures.count > 0 ? std::sqrt(sum_squares / figures.count) : 0;
  return figures;
}

// The points that a registered view still observes, in their order; dropped points' slots stay unused.
std::vector<Eigen::Vector3d> ObservedPoints(const Reconstruction& reconstruction) {
  std::vector<char> point_used(reconstruction.points().size(), 0);
  reconstruction.ForEachObservation([&](int, int point, const Eigen::Vector2d&) { point_used[point] = 1; });
  std::vector<Eigen::Vector3d> points;
  for (size_t p = 0; p < point_used.size(); ++p) {
    if (point_used[p]) points.push_back(reconstruction.points()[p]);
  }
  return points;
}

// How the views came out: registered, with a focal length from metadata or self-calibrated, and which not.
struct ViewCounts {
  int registered = 0;
  int metadata = 0;
  int self_calibrated = 0;
  std::vector<int> unregistered;
};

// Writes each view's pose, intrinsics, depth range and note (why it is not registered).
ViewCounts WriteViews(const Reconstruction& reconstruction,
                      const std::vector<std::vector<double>>& view_depths,
                      std::vector<SfmView>* views) {
  ViewCounts counts;
  const int n = static_cast<int>(views->size());
  for (int i = 0; i < n; ++i) {
    const ImageState& image = reconstruction.images()[i];
    SfmView& view = (*views)[i];
    view.registered = image.registered;
    view.note = image.registered ? "" : (image.note.empty() ? "not connected to the registered images" : image.note);
    view.camera = image.camera;
    view.cam_from_world = image.cam_from_world;
    view.observations = static_cast<int>(view_depths[i].size());
    view.depth_near = Percentile(view_depths[i], 0.02);
    view.depth_far = Percentile(view_depths[i], 0.98);
    if (!image.registered) {
      counts.unregistered.push_back(i);
      continue;
    }
    ++counts.registered;
    (image.known_intrinsics ? counts.metadata : counts.self_calibrated) += 1;
  }
  return counts;
}

// 8. Writes the result: the views, the points still observed, the figures, and a warning for each view not
// registered. Returns the view counts, for the focal length's source and warnings.
ViewCounts WriteResult(const Reconstruction& reconstruction, SfmResult* result) {
  SfmReport& report = result->report;
  const ObservationFigures figures = MeasureObservations(reconstruction);
  result->points = ObservedPoints(reconstruction);
  report.num_points = static_cast<int>(result->points.size());
  report.num_observations = figures.count;
  report.rms_px = figures.rms_px;
  const ViewCounts counts = WriteViews(reconstruction, figures.view_depths, &result->views);
  for (int i : counts.unregistered) {
    report.warnings.push_back("image " + std::to_string(i) + " is not registered: " + result->views[i].note);
  }
  report.num_registered = counts.registered;
  return counts;
}

// Warnings on the focal length: a sweep without a minimum, a metadata focal length held, a self-calibrated
// one unobservable (also flagged in the report), an initial pair that cannot fix it.
void AddFocalWarnings(int self_calibrated, bool refine_focal, const SfmOptions& options, SfmReport* report) {
  if (self_calibrated > 0 && !report->focal_sweep.empty()) {
    const double first = report->focal_sweep.front().first, last = report->focal_sweep.back().first;
    double best_focal = first, best_rms = std::numeric_limits<double>::infinity();
    for (const auto& [focal, rms] : report->focal_sweep) {
      if (rms < best_rms) {
        best_rms = rms;
        best_focal = focal;
      }
    }
    if (best_focal == first || best_focal == last) {
      report->warnings.push_back(
          Printf("self-calibrated focal length: the sweep's best (%.0f px) is at the end of "
                 "its range [%.0f, %.0f] px, no minimum; started from a normal lens (%.1f times "
                 "the longer side) and adjusted with every view, it may still be poorly "
                 "determined",
                 best_focal,
                 first,
                 last,
                 kNormalLensRatio));
    }
  }
  if (!refine_focal) {
    report->warnings.push_back(
        Printf("focal length held at the metadata's: the views are not rotated (at most %.2f deg "
               "between any two), so the images cannot refine it",
               report->max_view_rotation_deg));
  }
  if (self_calibrated > 0 && report->max_view_rotation_deg < options.min_rotation_for_focal_deg) {
    report->focal_observable = false;
    report->warnings.push_back(
        Printf("self-calibrated focal length is unobservable: the views are translated without "
               "rotation (at most %.2f deg between any two, need %.1f), so focal length and "
               "depth scale are one ambiguity; give the focal length from metadata (EXIF, a "
               "lens configuration) to measure depth",
               report->max_view_rotation_deg,
               options.min_rotation_for_focal_deg));
  }
  if (report->initial_homography_ratio < kPlanarHomographyRatio) {
    report->warnings.push_back(
        Printf("the initial pair sees a plane or a distant scene (one homography explains its "
               "matches to %.1f times their noise): poses hold, but a self-calibrated focal "
               "length is unreliable",
               report->initial_homography_ratio));
  }
}

}  // namespace

StatusOr<SfmResult> RunIncrementalSfm(const std::vector<SfmImage>& input, const SfmOptions& options) {
  const StageClock::time_point start = StageClock::now();
  PX_RETURN_IF_ERROR(options.Validate());
  if (input.empty()) return InvalidArgumentError("structure from motion: no images");
  const int n = static_cast<int>(input.size());
  SfmResult result;
  result.views.resize(n);
  SfmReport& report = result.report;
  report.num_images = n;
  const auto fail = [&](std::string reason) -> StatusOr<SfmResult> {
    report.success = false;
    report.failure = std::move(reason);
    report.total_ms = MsSince(start);
    return result;
  };

  // 1. Features.
  StageClock::time_point step = StageClock::now();
  PX_ASSIGN_OR_RETURN(std::vector<Features> features, DetectImageFeatures(input, options));
  report.features_ms = MsSince(step);
  std::vector<ImageState> images = StartImages(input, std::move(features), options);
  for (int i = 0; i < n; ++i) result.views[i].features = images[i].features.size();
  GroupIntrinsics(input, &images);

  // 2. All pairs: ratio + mutual matches, verified by a fundamental matrix.
  step = StageClock::now();
  PairMatching matching = MatchAllPairs(images, options);
  report.pairs = std::move(matching.figures);
  const std::vector<PairMatches> usable_pairs = UsablePairs(matching.verified, options);
  NoteUnmatchedImages(input, matching.verified, options, &images);
  const std::vector<Track> tracks = TracksOfPairs(images, usable_pairs);
  report.matching_ms = MsSince(step);
  // Failures from here on also say why each image was left out.
  const auto fail_with_notes = [&](std::string reason) {
    for (int i = 0; i < n; ++i) result.views[i].note = images[i].note;
    return fail(std::move(reason));
  };
  if (usable_pairs.empty()) return fail_with_notes(NoUsablePairReason(input, images, options));

  // 3. Focal length: from metadata, or swept on the pair with the most verified matches.
  step = StageClock::now();
  if (AnyUnknownIntrinsics(images)) report.focal_sweep = SweepFocalLength(usable_pairs, tracks, options, &images);

  // 4. The initial pair: enough parallax, then most matches weighted by parallax.
  const InitialPairChoice choice = ChooseInitialPair(images, usable_pairs, options);
  if (!choice.initial) return fail_with_notes(NoInitialPairReason(choice, usable_pairs, options));
  const PairGeometry& initial = *choice.initial;
  const PairMatches& initial_pair = usable_pairs[initial.pair];
  RecordInitialPair(initial, initial_pair, &report);

  Reconstruction reconstruction(images, tracks, options);
  StatusOr<BundleAdjustmentReport> two_view = InitialisePair(&reconstruction, initial_pair, initial.pose);
  if (!two_view.ok()) return fail_with_notes(two_view.status().message());

  // 5-6. The other images, the final adjustment, and a restart for parallel cameras. When the
  // initial pair is nearly parallel, the restart's reconstruction is built beside the main one on
  // another core; the finished main one still decides whether it is used, so the result is the
  // one building it afterwards gives.
  const bool build_beside =
      cv::getNumThreads() > 1 && RotationErrorDeg(initial.pose.b_from_a, Rigid3()) <
                                     kSpeculativeRestartFactor * options.parallel_restart_max_rotation_deg;
  Status registered = OkStatus();
  std::optional<ParallelCandidate> candidate;
  cv::parallel_for_(cv::Range(0, build_beside ? 2 : 1), [&](const cv::Range& range) {
    for (int task = range.start; task < range.end; ++task) {
      if (task == 0) {
        registered = RegisterAndAdjust(&reconstruction, initial_pair.view_a, initial_pair.view_b, options);
      } else {
        candidate = BuildParallelCandidate(images, tracks, initial_pair, initial.pose, options);
      }
    }
  });
  PX_RETURN_IF_ERROR(registered);
  PX_ASSIGN_OR_RETURN(
      const ParallelRestartReport restart,
      RestartIfParallel(&reconstruction, images, tracks, initial_pair, initial.pose, options, &candidate));
  if (restart.rebuilt) report.warnings.push_back(ParallelRestartWarning(restart));
  const bool refine_focal = reconstruction.FocalRefinable(options.min_rotation_for_focal_deg);
  report.reconstruction_ms = MsSince(step);

  // 7. World = the first registered image's camera; scale = median depth.
  NormaliseWorld(&reconstruction, options);

  // 8. Views, figures, warnings.
  const ViewCounts counts = WriteResult(reconstruction, &result);
  report.focal_source = counts.self_calibrated == 0
                            ? "metadata"
                            : (counts.metadata == 0 ? "self-calibrated" : "metadata and self-calibrated");
  report.max_view_rotation_deg = reconstruction.MaxRotationDeg();
  AddFocalWarnings(counts.self_calibrated, refine_focal, options, &report);
  if (report.num_registered < 2) return fail("fewer than two images registered");
  report.success = true;
  report.total_ms = MsSince(start);
  return result;
}

}  // namespace px::calib
