#include "pipeline/direct/plan_camera_path.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>

#include "pipeline/core/stage_clock.h"
#include "pipeline/direct/detail_size.h"
#include "pipeline/direct/morph_framing.h"
#include "pipeline/direct/pan_zoom_2d.h"
#include "pipeline/direct/scene_geometry.h"
#include "pipeline/direct/splat_coverage.h"
#include "pipeline/direct/subjects.h"
#include "pipeline/direct/taxonomy.h"

namespace px {

namespace {

// A morph looks like one scene moving where its correspondences agree forwards and backwards:
// over most of the frame, or, where most of the frame is flat (the dark, grainy surround of a
// film scan's lens circle, whose interpolated flow agrees with nothing and shows no second image
// whatever it is), over a clearer majority of the textured pixels, where the flow is measured.
constexpr double kMinMorphConsistency = 0.5;
constexpr double kMinTexturedMorphConsistency = 0.65;
constexpr double kMinTexturedShare = 0.02;  // of the frame: under it, texture is too scarce to judge by

// An automatic 3D move must show some parallax (parallax_measure.h: the share of the frame
// occluded at one end and seen at the other, both ways): the sets that make 3D moves show 0.13 %
// (a Nintendo 3DS pair) to 19 % (LLFF fern).
constexpr double kMinAutoMoveParallax = 0.0005;

// Flow that agrees both ways can still pair unrelated pixels (zero flow between two pictures that
// share nothing agrees with itself): the flow must also explain the pair, the views differing
// once warped by at most this share of their difference unwarped (real pairs: 0.06 to 0.22; two
// unrelated pictures of noise: 0.84).
constexpr double kMaxWarpedDifferenceShare = 0.5;

bool FlowExplainsPair(const direct::MorphReport& m) {
  return m.mean_abs_diff_warped <= kMaxWarpedDifferenceShare * m.mean_abs_diff_unwarped;
}

// How far the morph's consistency clears its bar (>= 1: the morph holds).
double MorphMargin(const direct::MorphReport& m) {
  const double whole = m.consistent_fraction / kMinMorphConsistency;
  if (m.textured_fraction < kMinTexturedShare) return whole;
  return std::max(whole, m.textured_consistent / kMinTexturedMorphConsistency);
}

std::string DescribeMorphConsistency(const direct::MorphReport& m) {
  char text[160];
  std::snprintf(text,
                sizeof(text),
                "%.0f%% of the frame's correspondences agree both ways, %.0f%% where it is textured (want %.0f%% "
                "or %.0f%%)",
                100 * m.consistent_fraction,
                100 * m.textured_consistent,
                100 * kMinMorphConsistency,
                100 * kMinTexturedMorphConsistency);
  return text;
}

// The pairs to morph between, in order of preference: the centre view with each of its nearest
// neighbours (the smallest baselines give the most reliable flow), up to kMorphCandidates; with
// two views, those two.
std::vector<std::pair<int, int>> MorphPairs(const std::vector<View>& views, int centre) {
  constexpr size_t kMorphCandidates = 3;
  std::vector<std::pair<double, int>> by_distance;
  const Eigen::Vector3d c = CameraCentre(views[centre].cam_from_world);
  for (size_t i = 0; i < views.size(); ++i) {
    if (static_cast<int>(i) == centre) continue;
    by_distance.emplace_back((CameraCentre(views[i].cam_from_world) - c).norm(), static_cast<int>(i));
  }
  std::sort(by_distance.begin(), by_distance.end());
  std::vector<std::pair<int, int>> pairs;
  for (size_t k = 0; k < std::min(kMorphCandidates, by_distance.size()); ++k) {
    const int other = by_distance[k].second;
    pairs.emplace_back(std::min(centre, other), std::max(centre, other));
  }
  return pairs;
}

CameraPath MorphPath(const View& a, const View& b, const std::vector<Subject>& subjects, const DirectOptions& options) {
  CameraPath path = BlankPath(PathKind::kMorph, "morph", a.camera, options.fps, options.duration_s);
  path.source_views = {a.id.value, b.id.value};
  path.subjects = subjects;
  for (const View* view : {&a, &b}) {
    CameraKeyframe key;
    key.t = view == &a ? 0.0 : 1.0;
    key.centre_in_world = CameraCentre(view->cam_from_world);
    key.cam_from_world_rotation = view->cam_from_world.rotation;
    key.focal_px = view->camera.fx;
    path.keyframes.push_back(key);
  }
  return path;
}

// `image` cut or padded (edges repeated) about its centre to `size`: tiles of a film scan differ
// by a few pixels, and the morph pairs pixels of one size.
cv::Mat CentredOnSize(const cv::Mat& image, cv::Size size) {
  if (image.size() == size) return image;
  const int cut_x = std::max(0, image.cols - size.width), cut_y = std::max(0, image.rows - size.height);
  cv::Mat cut = image(cv::Rect(cut_x / 2, cut_y / 2, image.cols - cut_x, image.rows - cut_y));
  const int pad_x = size.width - cut.cols, pad_y = size.height - cut.rows;
  cv::Mat out;
  cv::copyMakeBorder(cut, out, pad_y / 2, pad_y - pad_y / 2, pad_x / 2, pad_x - pad_x / 2, cv::BORDER_REPLICATE);
  return out;
}

// A morph with subjects pushes in on them (morph_framing.h), framed at the output's size.
void PushInOnSubjects(const direct::ViewMorph& morph, const DirectOptions& options, CameraPath* path) {
  if (path->subjects.empty()) return;
  const double zoom = direct::PlanMorphPushIn(morph, options, path);
  if (zoom <= 1) {
    path->notes.push_back("morph: no room to push in on the subjects; the whole frame is kept");
    return;
  }
  path->move = "morph_push_in";
  char text[120];
  std::snprintf(text,
                sizeof(text),
                "; pushing in on %zu subject%s to %.2fx",
                path->subjects.size(),
                path->subjects.size() == 1 ? "" : "s",
                zoom);
  path->reason += text;
}

struct Planner {
  const std::vector<View>& views;
  const std::vector<DepthMap>& depths;
  const DirectOptions& options;
  const DirectionContext& context;
  DirectionReport& report;
  int centre = 0;
  std::vector<Subject> subjects;

  // The morph between two views, if its correspondences hold; else the flat pan and zoom.
  StatusOr<CameraPath> Flat(const std::string& why) {
    report.fell_back = true;
    if (!why.empty()) report.notes.push_back(why);
    if (views.size() >= 2 && options.move != "pan_zoom_2d") {
      // Of the candidate pairs, the one whose correspondences hold best (a lens that fired while
      // the subject moved, or a neighbour posed badly, loses to the others).
      std::unique_ptr<direct::ViewMorph> best;
      int best_a = -1, best_b = -1;
      for (auto [ia, ib] : MorphPairs(views, centre)) {
        // The subjects' boxes are in the view they were found in: morph from it, so that the
        // frame can follow them along the flow (morph_framing.h).
        if (!subjects.empty() && subjects[0].view == views[ib].id.value) std::swap(ia, ib);
        const cv::Mat& image_a = views[ia].image;
        StatusOr<std::unique_ptr<direct::ViewMorph>> morph =
            direct::ViewMorph::Create(image_a, CentredOnSize(views[ib].image, image_a.size()), direct::MorphOptions{});
        const std::string pair =
            "views " + std::to_string(views[ia].id.value) + " and " + std::to_string(views[ib].id.value);
        if (!morph.ok()) {
          report.notes.push_back("morph of " + pair + " not used: " + morph.status().message());
          continue;
        }
        if (!FlowExplainsPair((*morph)->report())) {
          char text[200];
          std::snprintf(text,
                        sizeof(text),
                        "morph of %s not used: its flow does not bring the views together (they differ by %.1f levels, "
                        "%.1f once warped)",
                        pair.c_str(),
                        (*morph)->report().mean_abs_diff_unwarped,
                        (*morph)->report().mean_abs_diff_warped);
          report.notes.push_back(text);
          continue;
        }
        const double margin = MorphMargin((*morph)->report());
        if (margin < 1)
          report.notes.push_back("morph of " + pair + " not used: " + DescribeMorphConsistency((*morph)->report()));
        if (margin >= 1 && (best == nullptr || margin > MorphMargin(best->report()))) {
          best = std::move(morph).value();
          best_a = ia;
          best_b = ib;
        }
      }
      if (best != nullptr) {
        const View& a = views[best_a];
        const View& b = views[best_b];
        if (b.image.size() != a.image.size()) {
          report.notes.push_back("morph: view " + std::to_string(b.id.value) + " (" + std::to_string(b.image.cols) +
                                 "x" + std::to_string(b.image.rows) + ") cut or padded about its centre to view " +
                                 std::to_string(a.id.value) + "'s " + std::to_string(a.image.cols) + "x" +
                                 std::to_string(a.image.rows));
        }
        const direct::MorphReport& m = best->report();
        CameraPath path = MorphPath(views[best_a], views[best_b], subjects, options);
        char reason[400];
        std::snprintf(reason,
                      sizeof(reason),
                      "morph from view %d to view %d along dense correspondences (%s, %s, %.0f%% of matches moving "
                      "off their epipolar lines)",
                      views[best_a].id.value,
                      views[best_b].id.value,
                      DescribeMorphConsistency(m).c_str(),
                      m.epipolar ? "soft epipolar constraint" : "no epipolar geometry found",
                      100 * m.moving_fraction);
        path.reason = reason;
        report.morph = std::move(best);
        return path;
      }
    }
    return direct::PlanPanZoom2d(views[centre], subjects, options);
  }

  // The 3D move for the subjects found, with the taxonomy's fallbacks.
  StatusOr<CameraPath> ThreeD(const direct::SceneGeometry& scene,
                              const direct::SceneSamples& samples,
                              direct::CoverageProbe* search,
                              direct::CoverageProbe* verify,
                              const std::string& move,
                              const std::string& effect,
                              const std::vector<Subject>& move_subjects,
                              std::string* failure) {
    PX_ASSIGN_OR_RETURN(direct::MoveChoice choice,
                        direct::ChooseMove(static_cast<int>(move_subjects.size()), move, effect, options.seed));
    report.choice = choice.reason;
    direct::PlanContext plan;
    plan.scene = &scene;
    plan.samples = &samples;
    plan.subjects = move_subjects;
    plan.search = search;
    plan.verify = verify;
    plan.options = &options;
    std::map<std::string, direct::ValidRegion> regions;  // shared by the fallbacks below
    plan.regions = &regions;
    std::vector<direct::MoveChoice> tries = {choice};
    for (const direct::MoveChoice& fallback : direct::FallbackMoves(choice, static_cast<int>(move_subjects.size()))) {
      tries.push_back(fallback);
    }
    // Every move with the longest paths first; then, before giving up on 3D, every move again
    // with two more batches of candidate paths (plan_move.h, step 3).
    constexpr int kLastResortBatches = 3;
    std::string failures;
    for (const int batches : {1, kLastResortBatches}) {
      plan.path_batches = batches;
      if (batches > 1) {
        plan.first_batch = 1;  // the first batch of every move has just failed
        report.notes.push_back("no move could be planned with its " + std::to_string(options.search.num_longest) +
                               " longest candidate paths (" + failures + "): two more batches tried");
        failures.clear();
      }
      for (size_t i = 0; i < tries.size(); ++i) {
        StatusOr<CameraPath> path = direct::PlanMove(tries[i], plan, &report.plan);
        if (path.ok()) {
          if (i > 0) {
            report.fell_back = true;
            report.notes.push_back(std::string(direct::MoveName(choice.move)) + " could not be planned (" + failures +
                                   "); " + tries[i].reason);
          }
          path->reason = (i == 0 ? choice.reason : tries[i].reason) + "; " + path->reason;
          return path;
        }
        failures += (failures.empty() ? "" : "; ") + path.status().message();
      }
    }
    *failure = failures;
    return FailedPreconditionError(failures);
  }

  StatusOr<CameraPath> Shot(const direct::Shot& shot,
                            const direct::SceneGeometry* scene,
                            const direct::SceneSamples* samples,
                            direct::CoverageProbe* search,
                            direct::CoverageProbe* verify);
};

// Merges the segments' colour-effect layers: each key carries every segment's layers, neutral
// (amount 1) outside the segment that defines them, so that all keys list the same layers.
void HarmoniseEffects(const std::vector<int>& segment_of_key, CameraPath* path) {
  std::vector<std::pair<int, size_t>> slots;  // (segment, layer)
  std::vector<ColorEffect> first_definition;
  int last_segment = -1;
  for (size_t k = 0; k < path->keyframes.size(); ++k) {
    if (segment_of_key[k] == last_segment) continue;
    last_segment = segment_of_key[k];
    for (size_t l = 0; l < path->keyframes[k].effects.size(); ++l) {
      slots.emplace_back(last_segment, l);
      first_definition.push_back(path->keyframes[k].effects[l]);
    }
  }
  for (size_t k = 0; k < path->keyframes.size(); ++k) {
    std::vector<ColorEffect> merged;
    for (size_t s = 0; s < slots.size(); ++s) {
      const auto& [segment, layer] = slots[s];
      if (segment == segment_of_key[k] && layer < path->keyframes[k].effects.size()) {
        merged.push_back(path->keyframes[k].effects[layer]);
      } else {
        ColorEffect neutral = first_definition[s];
        neutral.amount = 1.0;
        merged.push_back(neutral);
      }
    }
    path->keyframes[k].effects = merged;
  }
}

StatusOr<CameraPath> Planner::Shot(const direct::Shot& shot,
                                   const direct::SceneGeometry* scene,
                                   const direct::SceneSamples* samples,
                                   direct::CoverageProbe* search,
                                   direct::CoverageProbe* verify) {
  DirectOptions shot_options = options;
  if (shot.fps > 0) shot_options.fps = shot.fps;
  if (shot.seed) shot_options.seed = *shot.seed;
  double total = shot.duration_s;
  if (!(total > 0)) {
    for (const direct::ShotSegment& s : shot.segments) total += s.duration_s;
  }
  if (!(total > 0)) total = options.duration_s;
  shot_options.duration_s = total;
  const std::vector<double> durations = shot.SegmentDurations(total);
  const double capture_focal = scene != nullptr ? scene->focal_px : views[centre].camera.fx;

  CameraPath path = BlankPath(
      PathKind::kNovelView, "shot", scene != nullptr ? scene->output : views[centre].camera, shot_options.fps, total);
  path.interpolation = direct::Interpolation::kLinear;
  std::vector<int> segment_of_key;
  std::string summary;
  double t0 = 0;
  for (size_t s = 0; s < shot.segments.size(); ++s) {
    const direct::ShotSegment& segment = shot.segments[s];
    const std::string where = "shot.segments[" + std::to_string(s) + "]";
    const double span = durations[s] / total;
    std::vector<CameraKeyframe> keys;
    char part[160];
    if (segment.authored()) {
      PX_ASSIGN_OR_RETURN(keys, direct::ResolveKeyframes(segment, capture_focal, where));
      if (segment.interpolation == direct::Interpolation::kCatmullRom) path.interpolation = segment.interpolation;
      std::snprintf(part, sizeof(part), "%zu keyframes over %.1f s", keys.size(), durations[s]);
    } else {
      if (scene == nullptr || samples == nullptr) {
        return FailedPreconditionError(where + ": move " + segment.move +
                                       " needs depth the pipeline can trust, and has none");
      }
      std::vector<Subject> move_subjects = subjects;
      if (!segment.subjects_px.empty()) {
        DirectOptions boxes = options;
        boxes.subject_boxes_px = segment.subjects_px;
        boxes.subject_view = segment.subject_view;
        PX_ASSIGN_OR_RETURN(direct::SubjectSearch found, direct::FindSubjects(views, depths, centre, nullptr, boxes));
        move_subjects = found.subjects;
      }
      std::vector<Subject> with_depth;
      for (const Subject& subject : move_subjects) {
        if (subject.depth_known) with_depth.push_back(subject);
      }
      DirectOptions segment_options = shot_options;
      segment_options.duration_s = std::max(1e-3, durations[s]);
      Planner sub{views, depths, segment_options, context, report, centre, with_depth};
      std::string failure;
      StatusOr<CameraPath> planned =
          sub.ThreeD(*scene, *samples, search, verify, segment.move, segment.effect, with_depth, &failure);
      if (!planned.ok()) return planned.status().WithContext(where);
      keys = planned->keyframes;
      for (const std::string& note : planned->notes) path.notes.push_back(note);
      for (const Subject& subject : planned->subjects) path.subjects.push_back(subject);
      std::snprintf(
          part, sizeof(part), "%s (%s) over %.1f s", planned->move.c_str(), planned->effect.c_str(), durations[s]);
    }
    summary += (summary.empty() ? "" : ", then ") + std::string(part);
    for (size_t k = 0; k < keys.size(); ++k) {
      CameraKeyframe key = keys[k];
      key.t = t0 + key.t * span;
      if (k == 0 && !path.keyframes.empty()) {
        // A chained segment starts where the previous one ended.
        const double jump = (key.centre_in_world - path.keyframes.back().centre_in_world).norm();
        if (jump > 1e-3 && segment.authored()) {
          char note[160];
          std::snprintf(note,
                        sizeof(note),
                        "%s starts %.0f mm from where the previous segment ended; it starts there",
                        where.c_str(),
                        1000 * jump);
          path.notes.push_back(note);
        }
        continue;
      }
      path.keyframes.push_back(key);
      segment_of_key.push_back(static_cast<int>(s));
    }
    t0 += span;
  }
  path.keyframes.front().t = 0.0;
  path.keyframes.back().t = 1.0;
  HarmoniseEffects(segment_of_key, &path);
  PX_RETURN_IF_ERROR(path.Validate().WithContext("shot"));
  path.reason = "authored shot: " + summary;
  // Authored paths are the user's to choose, but say where they leave the valid viewpoints.
  if (verify != nullptr) {
    double worst = 0, worst_t = 0;
    const int frames = std::max(options.search.verify_frames, 4 * static_cast<int>(shot.segments.size()) + 1);
    for (int i = 0; i < frames; ++i) {
      const double t = static_cast<double>(i) / (frames - 1);
      StatusOr<double> score = verify->HoleScore(path.CameraAt(t), path.PoseAt(t));
      if (score.ok() && *score > worst) {
        worst = *score;
        worst_t = t;
      }
    }
    report.plan.max_hole_score = worst;
    if (worst >= verify->valid_hole_score()) {
      char note[200];
      std::snprintf(note,
                    sizeof(note),
                    "the authored path leaves the valid viewpoints: H(V) %.1f at t = %.2f (valid below %.1f); "
                    "its holes are inpainted",
                    worst,
                    worst_t,
                    verify->valid_hole_score());
      path.notes.push_back(note);
    }
  }
  return path;
}

}  // namespace

double ConfidentDepthFraction(const View& view, const std::vector<DepthMap>& depths) {
  const DepthMap* depth = direct::FindDepth(depths, view.id);
  if (depth == nullptr || depth->depth_m.empty()) return 0.0;
  const bool has_confidence = depth->confidence.size() == depth->depth_m.size() && depth->confidence.type() == CV_32F;
  const cv::Mat known = depth->depth_m > 0;
  const cv::Mat sure = has_confidence ? (known & (depth->confidence >= 0.5)) : known;
  return static_cast<double>(cv::countNonZero(sure)) / static_cast<double>(depth->depth_m.total());
}

StatusOr<CameraPath> PlanCameraPath(const std::vector<View>& views,
                                    const std::vector<DepthMap>& depths,
                                    const DirectOptions& options,
                                    const DirectionContext& context,
                                    DirectionReport* report_out) {
  const StageClock::time_point start = StageClock::now();
  PX_RETURN_IF_ERROR(options.Validate());
  if (views.empty()) return InvalidArgumentError("direction: no views");
  DirectionReport local;
  DirectionReport& report = report_out != nullptr ? *report_out : local;
  report = DirectionReport{};
  Planner planner{views, depths, options, context, report};
  planner.centre = direct::CentreViewIndex(views);

  StatusOr<direct::SubjectSearch> found = direct::FindSubjects(
      views, depths, planner.centre, context.face_detector, options, context.centre_faces, context.metric_scale);
  if (found.ok()) {
    if (context.centre_faces != nullptr && context.centre_faces->view == views[planner.centre].id) {
      report.faces_before_ms = context.centre_faces->ms;
    }
    report.detector = found->detector;
    report.faces_detected = found->detections;
    report.subjects_ms = found->ms;
    planner.subjects = found->subjects;
    for (const std::string& note : found->notes) report.notes.push_back(note);
  } else {
    report.notes.push_back("subjects ignored: " + found.status().message());
    report.detector = "none (bad subject input)";
  }
  report.num_subjects = static_cast<int>(planner.subjects.size());

  // Why a 3D move is not attempted, if it is not.
  std::string no_3d;
  const double confident = ConfidentDepthFraction(views[planner.centre], depths);
  if (!context.depth_trusted) {
    no_3d = "depth or calibration not trusted: " + context.distrust_reason;
  } else if (views.size() < 2) {
    no_3d = "one view: no parallax to show";
  } else if (!context.coverage) {
    no_3d = "no renderer coverage to check viewpoints with";
  } else if (confident < options.min_confident_fraction) {
    char text[160];
    std::snprintf(text,
                  sizeof(text),
                  "only %.0f%% of the centre view's depth is confident (want %.0f%%)",
                  100 * confident,
                  100 * options.min_confident_fraction);
    no_3d = text;
  }
  if (options.move == "morph" || options.move == "pan_zoom_2d") no_3d = "requested " + options.move;

  StatusOr<CameraPath> path = FailedPreconditionError("not planned");
  const CameraModel& centre_camera = views[direct::CentreViewIndex(views)].camera;
  const OutputSize output_size = ResolveOutputSize(options.output, centre_camera.width, centre_camera.height);
  double framed_scale = 1;  // output pixels per centre-view pixel, once the scene is framed
  std::optional<direct::SceneGeometry> scene;
  std::optional<direct::SceneSamples> samples;
  std::optional<direct::SplatCoverage> splat;
  if (no_3d.empty()) {
    StatusOr<direct::SceneGeometry> described = direct::DescribeScene(views, depths);
    if (described.ok()) {
      scene = *described;
      // Everything below plans in the frame the viewer will see.
      scene->output = FrameOutputCamera(scene->output, output_size, &framed_scale);
      scene->focal_px *= framed_scale;
      scene->output_scale = framed_scale;
      samples = direct::SceneSamples::FromDepths(views, depths);
      if (options.search.splat_stride > 0) {
        splat =
            direct::SplatCoverage::FromDepths(views, depths, options.search.search_scale, options.search.splat_stride);
      }
    } else {
      no_3d = described.status().message();
    }
  }
  // The region search probes the splatted depth (splat_coverage.h) when asked, else the renderer
  // at search_scale; the chosen path's frames are always checked through the renderer.
  const CoverageFunction splat_function = splat ? splat->AsFunction() : CoverageFunction();
  // Frames enlarged beyond the capture's detail are drawn at that detail (detail_size.h), and
  // checked there. (The search keeps its fraction of the output: much smaller, its estimate
  // reads too many holes.)
  const double detail = framed_scale > direct::kDrawAtDetailAbove ? 1 / framed_scale : 1.0;
  const double verify_scale = std::min(options.search.verify_scale, detail);
  direct::CoverageProbe search(splat ? &splat_function : &context.coverage,
                               splat ? 1.0 : options.search.search_scale,
                               options.search.valid_hole_score,
                               /*concurrent=*/splat.has_value() || context.coverage_concurrent);
  direct::CoverageProbe verify(&context.coverage, verify_scale, options.search.valid_hole_score);
  // 3D moves need each subject's depth; a subject without it still frames a flat clip.
  std::vector<Subject> with_depth;
  for (const Subject& subject : planner.subjects) {
    if (subject.depth_known) with_depth.push_back(subject);
  }
  if (context.shot != nullptr) {
    if (!no_3d.empty() && !(views.size() == 2 && options.move == "auto")) {
      bool authored_only = true;
      for (const direct::ShotSegment& s : context.shot->segments) authored_only = authored_only && s.authored();
      if (!authored_only) {
        path = planner.Flat("shot not followed: its taxonomy moves need depth, and " + no_3d);
      }
    }
    if (!path.ok() && path.status().message() == "not planned") {
      StatusOr<CameraPath> shot_path = planner.Shot(*context.shot,
                                                    scene ? &*scene : nullptr,
                                                    samples ? &*samples : nullptr,
                                                    scene ? &search : nullptr,
                                                    scene ? &verify : nullptr);
      if (shot_path.ok()) {
        path = std::move(shot_path);
      } else {
        path = planner.Flat("shot not followed: " + shot_path.status().message());
      }
    }
  } else if (no_3d.empty()) {
    std::string failure;
    StatusOr<CameraPath> planned =
        planner.ThreeD(*scene, *samples, &search, &verify, options.move, options.effect, with_depth, &failure);
    if (planned.ok() && options.move == "auto" && report.plan.parallax < kMinAutoMoveParallax) {
      // A move that changes no occlusion is a zoom into a flat picture (depth flattened against
      // the far end of its range, or too little of it confident to show any): the morph, or the
      // flat pan and zoom, shows as much and resamples less.
      char text[200];
      std::snprintf(text,
                    sizeof(text),
                    "its best path (%s) shows almost no parallax: %.3f%% of the frame changes occlusion, want %.2f%%",
                    planned->move.c_str(),
                    100 * report.plan.parallax,
                    100 * kMinAutoMoveParallax);
      failure = text;
      planned = FailedPreconditionError(failure);
    }
    path = planned.ok() ? std::move(planned) : planner.Flat("no 3D move could be planned: " + failure);
  } else {
    const bool asked_flat = options.move == "morph" || options.move == "pan_zoom_2d";
    const bool paper_morph = views.size() == 2 && options.move == "auto";
    path = planner.Flat(asked_flat || paper_morph ? "" : "no 3D move: " + no_3d);
    if (path.ok()) {
      if (asked_flat || paper_morph) report.fell_back = false;
      path->reason = (asked_flat || paper_morph ? no_3d : "fallback") + std::string(": ") + path->reason;
    }
  }
  if (!path.ok()) return path.status().WithContext("direction");
  // Timing walks the same positions in another rhythm, so everything checked above still holds.
  path->timing = options.timing;
  // Paths planned in the framed scene have the output's size; the flat ones and a morph are cut
  // from their view's frame here.
  if (path->width == output_size.width && path->height == output_size.height) {
    if (path->kind == PathKind::kNovelView && scene) path->output_scale = framed_scale;
  } else {
    FitPathToOutput(&*path, output_size);
  }
  if (path->subjects.empty()) path->subjects = path->kind == PathKind::kNovelView ? with_depth : planner.subjects;
  if (path->kind == PathKind::kMorph && report.morph != nullptr) PushInOnSubjects(*report.morph, options, &*path);
  for (const std::string& note : report.notes) path->notes.push_back(note);
  report.coverage_probes = search.calls() + verify.calls();
  report.coverage_ms = search.ms() + verify.ms();
  report.verify_probes = verify.calls();
  report.verify_ms = verify.ms();
  report.total_ms = MsSince(start);
  PX_RETURN_IF_ERROR(path->Validate().WithContext("direction"));
  return path;
}

}  // namespace px
