#include "pipeline/direct/plan_move.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/core/utility.hpp>
#include <optional>

#include "pipeline/direct/aperture_search.h"
#include "pipeline/direct/framing.h"
#include "pipeline/direct/valid_viewpoints.h"

namespace px::direct {

namespace {

// Keyframes of a dolly zoom: dense enough that linear focal between them keeps the subject's
// height within 0.1 % (the exact focal varies with the distance to the subject, not linearly).
constexpr int kDollyZoomKeys = 9;
// Scale at which the parallax of candidate paths is measured (of the output size).
constexpr double kParallaxScale = 0.25;
// Framing may narrow a move's zoom to keep subjects inside, but not below this share of the
// focal length the move asks for: past that the move is not what it claims to be.
constexpr double kMinFocalShare = 0.5;
// Pulling an end back along its path to hold at the verify size (HoldEnds, step 4): the first
// pull, doubled each round, and the most (fractions of the path's length).
constexpr double kFirstPullBack = 0.05;
constexpr double kMaxPullBack = 0.4;
constexpr int kPullBackRounds = 5;

// Aims at `target` with `focal_px`; the frame's middle shows `shown` (target itself, or the
// surface in front of it).
FramingRule Aim(const SceneGeometry& scene,
                const Eigen::Vector3d& target,
                double focal_px,
                std::optional<Eigen::Vector3d> shown = std::nullopt) {
  return [&scene, target, focal_px, shown](const Eigen::Vector3d& centre) {
    Framing framing;
    framing.centre_in_world = centre;
    framing.cam_from_world = Rigid3::LookAt(centre, target, scene.up_in_world);
    framing.focal_px = focal_px;
    framing.aim_in_world = shown.value_or(target);
    return framing;
  };
}
FramingRule AimAtCentroid(const SceneGeometry& scene, double focal_px) {
  return Aim(scene, scene.centroid_in_world, focal_px, scene.centroid_surface_in_world);
}

// Looks straight along the capture axis (the capture frame's orientation) from any centre: a
// dolly zoom on a track. Moving along that axis with the focal keeping a subject's size keeps the
// subject's place in the frame too, wherever it sits.
FramingRule LookAlongAxis(const SceneGeometry& scene, double focal_px) {
  return [&scene, focal_px](const Eigen::Vector3d& centre) {
    Framing framing;
    framing.centre_in_world = centre;
    framing.cam_from_world = Rigid3(scene.rig_from_world.rotation, -(scene.rig_from_world.rotation * centre));
    framing.focal_px = focal_px;
    return framing;
  };
}

// `rule` with its focal narrowed until every subject is wholly inside the view (with the framing
// margin), so that the region search measures the views the path will use; a view that would
// need less than kMinFocalShare of the rule's focal cannot frame them (focal 0).
FramingRule FittingSubjects(FramingRule rule,
                            const SceneGeometry& scene,
                            const std::vector<Subject>& subjects,
                            double margin_px) {
  if (subjects.empty()) return rule;
  return [rule = std::move(rule), &scene, subjects, margin_px](const Eigen::Vector3d& centre) {
    Framing framing = rule(centre);
    if (!(framing.focal_px > 0)) return framing;
    const double most =
        MaxFocalKeepingInside(subjects, scene.OutputWithFocal(framing.focal_px), framing.cam_from_world, margin_px);
    framing.focal_px = most >= kMinFocalShare * framing.focal_px ? std::min(framing.focal_px, most) : 0.0;
    return framing;
  };
}

// What an Aim rule frames, as the region cache's key.
std::string AimKey(const Eigen::Vector3d& target, double focal_px) {
  char key[128];
  std::snprintf(key, sizeof(key), "aim (%.6f, %.6f, %.6f) at %.4f px", target.x(), target.y(), target.z(), focal_px);
  return key;
}

CameraKeyframe Key(double t, const Framing& framing) {
  CameraKeyframe key;
  key.t = t;
  key.centre_in_world = framing.centre_in_world;
  key.cam_from_world_rotation = framing.cam_from_world.rotation;
  key.focal_px = framing.focal_px;
  return key;
}

std::string Mm(const Eigen::Vector3d& p_in_rig) {
  char text[64];
  std::snprintf(
      text, sizeof(text), "(%.0f, %.0f, %.0f) mm", 1000 * p_in_rig.x(), 1000 * p_in_rig.y(), 1000 * p_in_rig.z());
  return text;
}

// Narrows focal lengths until every subject is wholly inside every frame. `uniform` scales all
// keys alike (a dolly zoom keeps its size ratio); otherwise each key first takes the most its
// own view allows. Fails when the subjects need less than kMinFocalShare of a key's focal.
Status KeepSubjectsInFrame(
    const std::vector<Subject>& subjects, double margin_px, bool uniform, CameraPath* path, double* scale) {
  *scale = 1.0;
  if (subjects.empty()) return OkStatus();
  std::vector<double> wanted;
  for (const CameraKeyframe& key : path->keyframes) wanted.push_back(key.focal_px);
  double uniform_scale = 1.0;
  for (CameraKeyframe& key : path->keyframes) {
    const double most = MaxFocalKeepingInside(subjects, path->CameraAt(key.t), key.CamFromWorld(), margin_px);
    if (uniform) {
      uniform_scale = std::min(uniform_scale, most / key.focal_px);
    } else {
      key.focal_px = std::min(key.focal_px, most);
    }
  }
  if (uniform) {
    for (CameraKeyframe& key : path->keyframes) key.focal_px *= uniform_scale;
  }
  // The share of the move's focal each key keeps; below kMinFocalShare the move is not itself.
  const auto check_shares = [&]() -> Status {
    *scale = 1.0;
    for (size_t i = 0; i < path->keyframes.size(); ++i) {
      const double share = path->keyframes[i].focal_px / wanted[i];
      *scale = std::min(*scale, share);
      if (!(share >= kMinFocalShare)) {
        char text[200];
        std::snprintf(text,
                      sizeof(text),
                      "the subjects fit in frame only at %.0f%% of the move's focal length at keyframe %zu",
                      100 * share,
                      i);
        return FailedPreconditionError(text);
      }
    }
    return OkStatus();
  };
  // The frames below only narrow the keys further: a key already short fails without them.
  PX_RETURN_IF_ERROR(check_shares());
  // Between keys the subjects move on their own curves: check every frame, narrow all keys by
  // the worst frame's shortfall, and repeat (it converges in one or two rounds).
  for (int round = 0; round < 4; ++round) {
    double worst = 1.0;
    for (int i = 0; i < path->NumFrames(); ++i) {
      const double t = path->FrameTime(i);
      const double most = MaxFocalKeepingInside(subjects, path->CameraAt(t), path->PoseAt(t), margin_px);
      worst = std::min(worst, most / path->FocalAt(t));
    }
    if (worst >= 1.0) break;
    for (CameraKeyframe& key : path->keyframes) key.focal_px *= 0.995 * worst;
  }
  PX_RETURN_IF_ERROR(check_shares());
  for (int i = 0; i < path->NumFrames(); ++i) {
    const double t = path->FrameTime(i);
    if (!SubjectsInside(subjects, path->CameraAt(t), path->PoseAt(t), 0.5 * margin_px)) {
      return FailedPreconditionError("a subject leaves frame " + std::to_string(i) + " however the zoom is narrowed");
    }
  }
  return OkStatus();
}

// The largest H(V) over `frames` frames evenly spread along the path, at the probe's size; it
// stops at the first frame over the threshold. `ends_score`: the ends' largest H(V), already
// measured at this size (then they are not again). `screen` (may be null): a cheaper probe by
// which the frames are measured the worst first, so that a path that fails is usually rejected
// by its first measurement at the probe's size (whether the path holds does not depend on the
// order).
StatusOr<double> WorstHoleScore(const CameraPath& path,
                                int frames,
                                CoverageProbe* probe,
                                std::optional<double> ends_score = std::nullopt,
                                CoverageProbe* screen = nullptr) {
  std::vector<std::pair<double, double>> order;  // (screened H(V), t), the worst first
  for (int i = ends_score ? 1 : 0; i < (ends_score ? frames - 1 : frames); ++i) {
    const double t = frames > 1 ? static_cast<double>(i) / (frames - 1) : 0.0;
    double screened = 0;
    if (screen != nullptr) {
      PX_ASSIGN_OR_RETURN(screened, screen->HoleScore(path.CameraAt(t), path.PoseAt(t)));
    }
    order.emplace_back(screened, t);
  }
  std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  double worst = ends_score.value_or(0.0);
  for (const auto& [screened, t] : order) {
    PX_ASSIGN_OR_RETURN(double score, probe->HoleScore(path.CameraAt(t), path.PoseAt(t)));
    worst = std::max(worst, score);
    if (worst >= probe->valid_hole_score()) break;  // early exit: this path is out
  }
  return worst;
}

Framing FramingOfKey(const CameraKeyframe& key) {
  Framing framing;
  framing.centre_in_world = key.centre_in_world;
  framing.cam_from_world = key.CamFromWorld();
  framing.focal_px = key.focal_px;
  return framing;
}

// The largest aperture valid at every key in `keys` (searched at the search size, confirmed at
// the verify size, halved until confirmed).
StatusOr<double> PathAperture(const CameraPath& path, const std::vector<size_t>& keys, const PlanContext& context) {
  const DirectOptions& options = *context.options;
  double aperture = options.max_aperture_m;
  for (size_t k : keys) {
    PX_ASSIGN_OR_RETURN(ApertureResult found,
                        LargestValidAperture(FramingOfKey(path.keyframes[k]),
                                             *context.scene,
                                             context.search,
                                             options.max_aperture_m,
                                             0.02 * options.max_aperture_m));
    aperture = std::min(aperture, found.aperture_m);
  }
  for (int attempt = 0; attempt < 4 && aperture > 0; ++attempt) {
    bool valid = true;
    for (size_t k : keys) {
      const Framing key = FramingOfKey(path.keyframes[k]);
      const CameraModel camera = context.scene->OutputWithFocal(key.focal_px);
      for (const Framing& corner : ApertureCorners(key, aperture)) {
        PX_ASSIGN_OR_RETURN(bool ok, context.verify->Valid(camera, corner.cam_from_world));
        valid = valid && ok;
        if (!valid) break;
      }
      if (!valid) break;
    }
    if (valid) return aperture;
    aperture *= 0.5;
  }
  return 0.0;
}

// A colour-effect layer on the subject: its box around the face quadrilateral, a quarter of the
// face width wider on each side and half a face width deep each way.
ColorEffect SubjectLayer(const Subject& subject, Effect effect, double amount) {
  ColorEffect layer;
  layer.kind = (effect == Effect::kSaturation || effect == Effect::kDesaturateBackground)
                   ? ColorEffectKind::kSaturation
                   : ColorEffectKind::kBrightness;
  layer.invert = effect == Effect::kDesaturateBackground || effect == Effect::kDimBackground;
  layer.amount = amount;
  Eigen::Vector3d lo = subject.corners_in_world[0], hi = lo;
  for (const Eigen::Vector3d& c : subject.corners_in_world) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  const double width = std::max(subject.WidthM(), 1e-3);
  const Eigen::Vector3d pad(0.25 * width, 0.25 * width, 0.5 * width);
  layer.region_min_in_world = lo - pad;
  layer.region_max_in_world = hi + pad;
  layer.falloff_m = 0.25 * width;
  return layer;
}

double EffectTarget(Effect effect) {
  switch (effect) {
    case Effect::kSaturation:
      return 1.6;
    case Effect::kBrightness:
      return 1.35;
    case Effect::kDesaturateBackground:
      return 0.2;
    case Effect::kDimBackground:
      return 0.55;
    default:
      return 1.0;
  }
}

// The region's candidate endpoints: its forward or backward extremes, or both.
std::vector<Candidate> Candidates(const ValidRegion& region, bool front, bool both_ways) {
  if (!both_ways) return front ? region.front : region.back;
  std::vector<Candidate> all = region.front;
  all.insert(all.end(), region.back.begin(), region.back.end());
  return all;
}

// A candidate path: one start and one end candidate, and what framing, the verify size and the
// parallax measure make of it.
struct Pair {
  size_t a = 0, b = 0;
  double length = 0, parallax = 0, focal_scale = 1;
  CameraPath path;
  std::optional<Framing> start_pulled, end_pulled;  // ends pulled back to hold at the verify size
  std::optional<double> ends_score;                 // the ends' largest H(V) at the verify size
  double max_hole_score = 0;                        // over its checked frames, once it holds (verify size)
};

// What the steps of PlanMove share: the move's subjects, each end's framing rule, valid region and
// candidates, and the candidate paths.
struct MovePlan {
  MovePlan(const MoveChoice& move_choice, const PlanContext& plan_context, MovePlanReport* plan_report)
      : choice(move_choice),
        context(plan_context),
        scene(*plan_context.scene),
        options(*plan_context.options),
        report(plan_report),
        name(MoveName(move_choice.move)) {}

  const MoveChoice& choice;
  const PlanContext& context;
  const SceneGeometry& scene;
  const DirectOptions& options;
  MovePlanReport* report;
  const std::string name;
  const Subject* first = nullptr;  // the subjects the move frames, in the choice's order
  const Subject* second = nullptr;

  Sweep sweep = Sweep::kGrid;
  FramingRule start_rule, end_rule;
  bool start_front = true, end_front = true, reverse = false, dolly_zoom = false;
  // The dolly between two subjects keeps both in frame: a close-up far forwards loses the other
  // subject past the frame's edge, so its ends come from the forward and the backward extremes.
  bool both_ways = false;
  bool along_axis = false;  // a dolly zoom that looks along the capture axis, not at its subject
  std::string start_what, end_what;
  std::string start_key, end_key;  // what each rule frames, for the region cache ("" = not shared)
  std::vector<Subject> framed;     // the subjects framing keeps in view
  double margin_px = 0;

  ValidRegion start_region, end_region;
  std::vector<Candidate> starts, ends;
  bool shared = false;         // the ends share the start's region (the establishing dolly)
  std::vector<Pair> pairs;     // every candidate pair, longest first
  size_t next_pair = 0;        // the first of `pairs` no batch has taken yet
  std::vector<Pair> measured;  // the batch: the longest that keep their subjects in frame, most parallax first
  std::vector<char> excluded_starts, excluded_ends;  // candidates a failed batch's paths all went through
  std::string last_failure = "no candidate";
};

// The subjects the move frames, in the choice's order: a 3D move needs enough of them, each with
// a known depth.
Status ChooseSubjects(MovePlan* plan) {
  const std::vector<Subject>& subjects = plan->context.subjects;
  const std::string& name = plan->name;
  const int needed = SubjectsNeeded(plan->choice.move);
  if (static_cast<int>(subjects.size()) < needed) {
    return FailedPreconditionError(name + " needs " + std::to_string(needed) + " subjects, have " +
                                   std::to_string(subjects.size()));
  }
  const Subject* first = needed >= 1 ? &subjects[0] : nullptr;
  const Subject* second = needed >= 2 ? &subjects[1] : nullptr;
  if (needed >= 2 && plan->choice.swap_subjects) std::swap(first, second);
  if (needed == 1 && plan->choice.swap_subjects && subjects.size() >= 2) first = &subjects[1];
  for (const Subject* s : {first, second}) {
    if (s != nullptr && !s->depth_known) {
      return FailedPreconditionError(name + ": a subject has no known depth to plan a 3D move around");
    }
  }
  plan->first = first;
  plan->second = second;
  return OkStatus();
}

// Each end's framing rule (where it looks and its focal length, 4.2.3), the extreme of its valid
// region it takes, and how the region is searched: the move's definition.
void ChooseEndRules(MovePlan* plan) {
  const SceneGeometry& scene = plan->scene;
  const DirectOptions& options = plan->options;
  const Subject* first = plan->first;
  const Subject* second = plan->second;
  const double f = scene.focal_px;
  const double zoomed = options.zoom_in * f;
  const Eigen::Vector3d& centroid = scene.centroid_in_world;
  switch (plan->choice.move) {
    case Move::kEstablishingDolly:
      plan->start_rule = plan->end_rule = AimAtCentroid(scene, f);
      plan->start_key = plan->end_key = AimKey(centroid, f);
      plan->start_what = plan->end_what = "the scene centroid at f";
      break;
    case Move::kEstablishingDollyOut:
      plan->sweep = Sweep::kAxis;
      plan->start_rule = AimAtCentroid(scene, zoomed);
      plan->end_rule = AimAtCentroid(scene, f);
      plan->start_key = AimKey(centroid, zoomed);
      plan->end_key = AimKey(centroid, f);
      plan->end_front = false;
      plan->start_what = "the scene centroid at " + std::to_string(options.zoom_in).substr(0, 4) + "f";
      plan->end_what = "the scene centroid at f";
      break;
    case Move::kDollyOut:
      plan->start_rule = Aim(scene, first->LowerHalfCentreInWorld(), zoomed);
      plan->end_rule = AimAtCentroid(scene, f);
      plan->start_key = AimKey(first->LowerHalfCentreInWorld(), zoomed);
      plan->end_key = AimKey(centroid, f);
      plan->end_front = false;
      plan->start_what = "the " + first->source + " at " + std::to_string(options.zoom_in).substr(0, 4) + "f";
      plan->end_what = "the scene centroid at f";
      break;
    case Move::kDollyIn:
      plan->start_rule = AimAtCentroid(scene, f);
      plan->end_rule = Aim(scene, first->LowerHalfCentreInWorld(), zoomed);
      plan->start_key = AimKey(centroid, f);
      plan->end_key = AimKey(first->LowerHalfCentreInWorld(), zoomed);
      plan->start_front = false;
      plan->start_what = "the scene centroid at f";
      plan->end_what = "the " + first->source + " at " + std::to_string(options.zoom_in).substr(0, 4) + "f";
      break;
    case Move::kDollyZoomIn:
      plan->reverse = true;
      [[fallthrough]];
    case Move::kDollyZoomOut:
      plan->sweep = Sweep::kAxis;
      plan->dolly_zoom = true;
      plan->start_rule = Aim(scene, first->LowerHalfCentreInWorld(), f);
      plan->start_key = AimKey(first->LowerHalfCentreInWorld(), f);
      plan->end_front = false;
      plan->start_what = "the " + first->source + " at f";
      plan->end_what = "the " + first->source + ", zoomed to keep its size";
      break;
    case Move::kDolly: {
      plan->start_rule = Aim(scene, first->LowerHalfCentreInWorld(), zoomed);
      plan->start_key = AimKey(first->LowerHalfCentreInWorld(), zoomed);
      // The paper's size ratio from the reference view; the exact ratio is set once the
      // endpoints are known.
      const double ratio = first->box_px.height / std::max(1.0, second->box_px.height);
      plan->end_rule = Aim(scene, second->LowerHalfCentreInWorld(), zoomed * ratio);
      plan->end_key = AimKey(second->LowerHalfCentreInWorld(), zoomed * ratio);
      plan->start_what = "the first subject at " + std::to_string(options.zoom_in).substr(0, 4) + "f";
      plan->end_what = "the second subject at its size";
      plan->both_ways = true;
      break;
    }
  }
}

// Subjects that framing keeps in view: every subject with a known depth. The ends' rules fit
// them, so the region search measures the views the path will use (a dolly zoom's focal is fixed
// by its subject's size instead).
void FitRulesToSubjects(MovePlan* plan) {
  for (const Subject& s : plan->context.subjects) {
    if (s.depth_known) plan->framed.push_back(s);
  }
  plan->margin_px = plan->options.framing_margin * plan->scene.output.width;
  if (plan->dolly_zoom) return;
  plan->start_rule = FittingSubjects(std::move(plan->start_rule), plan->scene, plan->framed, plan->margin_px);
  plan->end_rule = FittingSubjects(std::move(plan->end_rule), plan->scene, plan->framed, plan->margin_px);
  if (!plan->framed.empty()) {
    plan->start_key += plan->start_key.empty() ? "" : " fitting subjects";
    plan->end_key += plan->end_key.empty() ? "" : " fitting subjects";
  }
}

// The valid region for `rule`, reused from earlier moves whose rule framed the same (`key`; ""
// = not shared) and searched the same way, so the renderer is not probed again.
StatusOr<ValidRegion> FindRegion(
    const MovePlan& plan, const FramingRule& rule, const std::string& key, bool front, bool back) {
  const PlanContext& context = plan.context;
  std::string full;
  if (!key.empty() && context.regions != nullptr) {
    full = key + (plan.sweep == Sweep::kAxis ? " axis" : " grid") + (front ? " front" : "") + (back ? " back" : "");
    const auto found = context.regions->find(full);
    if (found != context.regions->end()) return found->second;
  }
  PX_ASSIGN_OR_RETURN(
      ValidRegion region,
      FindValidViewpoints(plan.scene, rule, context.search, plan.options.search, plan.sweep, front, back));
  if (!full.empty()) (*context.regions)[full] = region;
  return region;
}

// The start's valid region and candidate endpoints; fails when no viewpoint frames the start.
Status FindStarts(MovePlan* plan) {
  PX_ASSIGN_OR_RETURN(plan->start_region,
                      FindRegion(*plan,
                                 plan->start_rule,
                                 plan->start_key,
                                 plan->start_front || plan->both_ways,
                                 !plan->start_front || plan->both_ways));
  plan->starts = Candidates(plan->start_region, plan->start_front, plan->both_ways);
  // A dolly zoom aimed at a subject off the axis turns every viewpoint past the rays the lenses
  // saw (two_faces: none of 144 grid positions holds the face at f). Then it looks along the axis.
  if (plan->starts.empty() && plan->dolly_zoom) {
    plan->along_axis = true;
    plan->start_rule = LookAlongAxis(plan->scene, plan->scene.focal_px);
    PX_ASSIGN_OR_RETURN(plan->start_region,
                        FindRegion(*plan, plan->start_rule, "", plan->start_front, !plan->start_front));
    plan->starts = Candidates(plan->start_region, plan->start_front, plan->both_ways);
  }
  plan->report->valid_cells_start = plan->start_region.valid_cells;
  if (plan->starts.empty()) {
    return FailedPreconditionError(plan->name + ": no valid viewpoint frames the start (" + plan->start_what +
                                   ") among " + std::to_string(plan->start_region.cells) + " positions");
  }
  return OkStatus();
}

// A dolly zoom's start may be so near the subject that even the capture plane needs more than
// max_dolly_zoom to keep its size: then it starts farther back (still between z = 0 and the front
// surface, inside the valid region along the axis), so the zoom has room to run.
Status MoveDollyZoomStartBack(MovePlan* plan) {
  const SceneGeometry& scene = plan->scene;
  const PlanContext& context = plan->context;
  Candidate& start = plan->starts.front();
  const Eigen::Vector3d start_in_rig = scene.RigFromWorld(start.framing.centre_in_world);
  const double subject_z = scene.RigFromWorld(plan->first->CentreInWorld()).z();
  const double nearest_z =
      subject_z - (subject_z - std::min(0.0, start_in_rig.z())) / (0.9 * plan->options.max_dolly_zoom);
  if (start_in_rig.z() > nearest_z && nearest_z > 0) {
    start.framing =
        plan->start_rule(scene.WorldFromRig(Eigen::Vector3d(start_in_rig.x(), start_in_rig.y(), nearest_z)));
    PX_ASSIGN_OR_RETURN(
        start.hole_score,
        context.search->HoleScore(scene.OutputWithFocal(start.framing.focal_px), start.framing.cam_from_world));
    if (!(start.hole_score < context.search->valid_hole_score())) {
      return FailedPreconditionError(plan->name + ": the start " +
                                     Mm(scene.RigFromWorld(start.framing.centre_in_world)) +
                                     " far enough back for the zoom to keep the subject's size is not valid");
    }
  }
  return OkStatus();
}

// A dolly zoom's far end keeps the subject at the start's size: focal grows with the distance, up
// to max_dolly_zoom (beyond it the rule declines to frame, which ends the search).
FramingRule DollyZoomEndRule(const MovePlan& plan) {
  const SceneGeometry& scene = plan.scene;
  const Framing start = plan.starts.front().framing;
  const Subject subject = *plan.first;
  const double start_height = ProjectedHeightPx(subject, scene.OutputWithFocal(1.0), start.cam_from_world);
  const double target_height = start_height * start.focal_px;
  const double limit = plan.options.max_dolly_zoom * start.focal_px;
  const FramingRule aim =
      plan.along_axis ? LookAlongAxis(scene, 1.0) : Aim(scene, plan.first->LowerHalfCentreInWorld(), 1.0);
  return [&scene, aim, subject, target_height, limit](const Eigen::Vector3d& centre) {
    Framing framing = aim(centre);
    const double unit = ProjectedHeightPx(subject, scene.OutputWithFocal(1.0), framing.cam_from_world);
    framing.focal_px = unit > 0 ? target_height / unit : 0.0;
    if (framing.focal_px > limit) framing.focal_px = 0;  // past the zoom range
    return framing;
  };
}

// The end's valid region and candidate endpoints (the establishing dolly's ends share the start's
// region); fails when no viewpoint frames the end.
Status FindEnds(MovePlan* plan) {
  plan->shared = plan->choice.move == Move::kEstablishingDolly;
  if (plan->shared) {
    plan->end_region = plan->start_region;
  } else {
    PX_ASSIGN_OR_RETURN(plan->end_region,
                        FindRegion(*plan,
                                   plan->end_rule,
                                   plan->dolly_zoom ? "" : plan->end_key,
                                   plan->end_front || plan->both_ways,
                                   !plan->end_front || plan->both_ways));
  }
  plan->report->valid_cells_end = plan->end_region.valid_cells;
  plan->ends = Candidates(plan->end_region, plan->end_front, plan->both_ways);
  if (plan->ends.empty()) {
    return FailedPreconditionError(plan->name + ": no valid viewpoint frames the end (" + plan->end_what + ") among " +
                                   std::to_string(plan->end_region.cells) + " positions");
  }
  return OkStatus();
}

// Every start x end pair at least 1 mm long, longest first (the longest move the ends allow).
Status ListCandidatePairs(MovePlan* plan) {
  const double min_length = 1e-3;
  for (size_t a = 0; a < plan->starts.size(); ++a) {
    for (size_t b = plan->shared ? a + 1 : 0; b < plan->ends.size(); ++b) {
      const double length = (plan->starts[a].framing.centre_in_world - plan->ends[b].framing.centre_in_world).norm();
      if (length >= min_length) plan->pairs.push_back({a, b, length, 0, 1, {}});
    }
  }
  plan->report->candidate_paths = static_cast<int>(plan->pairs.size());
  if (plan->pairs.empty()) return FailedPreconditionError(plan->name + ": every candidate path is shorter than 1 mm");
  std::stable_sort(
      plan->pairs.begin(), plan->pairs.end(), [](const Pair& x, const Pair& y) { return x.length > y.length; });
  return OkStatus();
}

// The pair's ends as the region search found them, or pulled back to hold at the verify size.
Framing StartFraming(const MovePlan& plan, const Pair& pair) {
  return pair.start_pulled.value_or(plan.starts[pair.a].framing);
}
Framing EndFraming(const MovePlan& plan, const Pair& pair) {
  return pair.end_pulled.value_or(plan.ends[pair.b].framing);
}

// The path for a pair, its subjects kept in frame (or why they cannot be).
Status FramePath(const MovePlan& plan, Pair* pair) {
  const SceneGeometry& scene = plan.scene;
  const DirectOptions& options = plan.options;
  Framing start = StartFraming(plan, *pair);
  Framing end = EndFraming(plan, *pair);
  CameraPath path = BlankPath(PathKind::kNovelView, plan.name, scene.output, options.fps, options.duration_s);
  if (plan.choice.move == Move::kDolly) {
    // The second subject ends at the size the first started at.
    const double h1 = ProjectedHeightPx(*plan.first, scene.OutputWithFocal(start.focal_px), start.cam_from_world);
    const double h2_unit = ProjectedHeightPx(*plan.second, scene.OutputWithFocal(1.0), end.cam_from_world);
    if (h1 > 0 && h2_unit > 0) end.focal_px = h1 / h2_unit;
  }
  if (plan.dolly_zoom) {
    for (int k = 0; k < kDollyZoomKeys; ++k) {
      const double t = static_cast<double>(k) / (kDollyZoomKeys - 1);
      const Eigen::Vector3d centre = (1 - t) * start.centre_in_world + t * end.centre_in_world;
      Framing framing = plan.end_rule(centre);
      if (k == 0) framing = start;
      if (!(framing.focal_px > 0)) framing.focal_px = end.focal_px;
      path.keyframes.push_back(Key(t, framing));
    }
  } else {
    path.keyframes = {Key(0, start), Key(1, end)};
  }
  if (plan.reverse) {
    std::reverse(path.keyframes.begin(), path.keyframes.end());
    for (CameraKeyframe& key : path.keyframes) key.t = 1.0 - key.t;
    path.keyframes.front().t = 0.0;
    path.keyframes.back().t = 1.0;
  }
  PX_RETURN_IF_ERROR(KeepSubjectsInFrame(plan.framed, plan.margin_px, plan.dolly_zoom, &path, &pair->focal_scale));
  pair->path = std::move(path);
  return OkStatus();
}

// Whether the search-size probe finds a frame between the pair's ends far outside the valid
// viewpoints (H(V) at least kScreenedOutFactor times the valid score). The ends lie in valid
// cells, but the straight way between two of them can cross a region no view covers (between a
// stereo pair's two narrow valid regions); the verify size would turn such a path down at many
// times the cost, and a batch of them can crowd out every path that holds. The margin keeps
// the search size's reading, which can differ from the output size's, from deciding close calls.
bool LeavesValidRegionOnTheWay(MovePlan* plan, const Pair& pair) {
  constexpr double kScreenedOutFactor = 4;
  CoverageProbe* search = plan->context.search;
  if (search == nullptr) return false;
  const int frames = plan->options.search.verify_frames;
  for (int i = 1; i < frames - 1; ++i) {
    const double t = static_cast<double>(i) / (frames - 1);
    StatusOr<double> score = search->HoleScore(pair.path.CameraAt(t), pair.path.PoseAt(t));
    if (score.ok() && *score >= kScreenedOutFactor * search->valid_hole_score()) {
      char text[160];
      std::snprintf(text, sizeof(text), "a frame between its ends has H(V) %.2f at the search size", *score);
      plan->last_failure = text;
      return true;
    }
  }
  return false;
}

// The `num_longest` longest pairs that keep their subjects in frame: framing costs no coverage
// probe, so it is checked first. With `screen` (the last-resort batches, once every move's
// longest paths have failed), also those that stay near the valid viewpoints on their way,
// screened at the search size for at most 8 * num_longest pairs a batch (then as they come):
// then a shorter path that holds is better than none, but a fallback move's longest paths come
// before it (they usually show the scene better).
void KeepFramedPairs(MovePlan* plan, bool screen) {
  const size_t keep = static_cast<size_t>(plan->options.search.num_longest);
  const int max_screened_out = 8 * static_cast<int>(keep);
  int screened_out = 0;
  plan->measured.clear();
  for (; plan->next_pair < plan->pairs.size() && plan->measured.size() < keep; ++plan->next_pair) {
    Pair& pair = plan->pairs[plan->next_pair];
    if (plan->excluded_starts[pair.a] || plan->excluded_ends[pair.b]) continue;
    Status framed_ok = FramePath(*plan, &pair);
    if (!framed_ok.ok()) {
      plan->last_failure = framed_ok.message();
      continue;
    }
    if (screen && screened_out < max_screened_out && LeavesValidRegionOnTheWay(plan, pair)) {
      ++screened_out;
      continue;
    }
    plan->measured.push_back(std::move(pair));
  }
}

// After a batch in which no path held: the start and end candidates that most of its paths went
// through are left out of the next. The longest paths share their farthest ends, and a cell's
// farthest valid position can lie on an island that the way there leaves (a position far
// forwards is valid where the ones between it and the capture plane are not), so one such end
// can take a whole batch with it.
void ExcludeEndsOfFailedBatch(MovePlan* plan) {
  std::vector<int> start_uses(plan->starts.size(), 0), end_uses(plan->ends.size(), 0);
  for (const Pair& pair : plan->measured) {
    ++start_uses[pair.a];
    ++end_uses[pair.b];
  }
  const int most = static_cast<int>(plan->measured.size()) / 2;
  for (size_t a = 0; a < start_uses.size(); ++a) plan->excluded_starts[a] |= start_uses[a] > most;
  for (size_t b = 0; b < end_uses.size(); ++b) plan->excluded_ends[b] |= end_uses[b] > most;
  if (plan->shared) {  // one list of candidates serves both ends
    for (size_t i = 0; i < plan->starts.size(); ++i) {
      plan->excluded_starts[i] = plan->excluded_ends[i] = plan->excluded_starts[i] | plan->excluded_ends[i];
    }
  }
}

// The kept pairs' parallax, from each end's view of the scene (made once per end: the pairs share
// ends), on every core; then most parallax first.
void MeasureParallax(MovePlan* plan) {
  const SceneGeometry& scene = plan->scene;
  const std::vector<Candidate>& starts = plan->starts;
  const std::vector<Candidate>& ends = plan->ends;
  std::vector<Pair>& measured = plan->measured;
  std::vector<const Framing*> ends_seen;
  for (const Pair& pair : measured) {
    for (const Framing* end : std::array<const Framing*, 2>{&starts[pair.a].framing, &ends[pair.b].framing}) {
      if (std::find(ends_seen.begin(), ends_seen.end(), end) == ends_seen.end()) ends_seen.push_back(end);
    }
  }
  const auto small_camera = [&](const Framing& end) {
    return scene.OutputWithFocal(end.focal_px).Scaled(kParallaxScale);
  };
  std::vector<cv::Mat> seen(ends_seen.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(ends_seen.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      seen[i] = plan->context.samples->DepthSeenFrom(small_camera(*ends_seen[i]), ends_seen[i]->cam_from_world);
    }
  });
  const auto seen_from = [&](const Framing& end) -> const cv::Mat& {
    return seen[std::find(ends_seen.begin(), ends_seen.end(), &end) - ends_seen.begin()];
  };
  cv::parallel_for_(cv::Range(0, static_cast<int>(measured.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const Framing& a = starts[measured[i].a].framing;
      const Framing& b = ends[measured[i].b].framing;
      measured[i].parallax = ParallaxScore(
          seen_from(a), small_camera(a), a.cam_from_world, seen_from(b), small_camera(b), b.cam_from_world);
    }
  });
  std::stable_sort(
      measured.begin(), measured.end(), [](const Pair& x, const Pair& y) { return x.parallax > y.parallax; });
}

// Whether the pair's end frames hold at the verify size, pulling an end back where it does not.
// The search pushes every end to the farthest z its reduced-size probe calls valid, so the ends
// sit on the threshold as that probe sees it, and the frames the path uses are framed once more
// (the dolly's size ratio, subjects kept in frame by a wider zoom): at the verify size an end can
// read just past it (H 2.1 on the 640x480 one-face dolly-in). Such an end is pulled back along
// the path towards the other, re-framed by its rule, until the path's end frame holds at the
// verify size (at most kMaxPullBack of the path; the dolly zoom keeps its ends).
StatusOr<bool> HoldEnds(const MovePlan& plan, Pair* pair) {
  if (plan.dolly_zoom) return true;
  CoverageProbe* verify = plan.context.verify;
  const Framing& a = plan.starts[pair->a].framing;
  const Framing& b = plan.ends[pair->b].framing;
  double pull[2] = {0, 0};  // start, end: fraction of the path pulled back
  for (int round = 0; round < kPullBackRounds; ++round) {
    bool held = true;
    double ends_score = 0;
    for (int side = 0; side < 2; ++side) {
      const double t = side == 0 ? 0.0 : 1.0;
      PX_ASSIGN_OR_RETURN(double score, verify->HoleScore(pair->path.CameraAt(t), pair->path.PoseAt(t)));
      ends_score = std::max(ends_score, score);
      if (score < verify->valid_hole_score()) continue;
      held = false;
      pull[side] = pull[side] == 0 ? kFirstPullBack : 2 * pull[side];
      if (pull[side] > kMaxPullBack) return false;
    }
    if (held) {
      pair->ends_score = ends_score;
      return true;
    }
    if (pull[0] > 0)
      pair->start_pulled = plan.start_rule(a.centre_in_world + pull[0] * (b.centre_in_world - a.centre_in_world));
    if (pull[1] > 0)
      pair->end_pulled = plan.end_rule(b.centre_in_world + pull[1] * (a.centre_in_world - b.centre_in_world));
    for (const std::optional<Framing>& pulled : {pair->start_pulled, pair->end_pulled}) {
      if (pulled && !(pulled->focal_px > 0)) return false;  // the rule cannot frame from there
    }
    if (!FramePath(plan, pair).ok()) return false;
  }
  return false;
}

// The parallax and length of a path whose ends were pulled back, as it now is, and a note of how
// far they moved.
void MeasurePulledPath(const MovePlan& plan, Pair* pair) {
  CameraPath& path = pair->path;
  pair->parallax = ParallaxScore(*plan.context.samples,
                                 path.CameraAt(0).Scaled(kParallaxScale),
                                 path.PoseAt(0),
                                 path.CameraAt(1).Scaled(kParallaxScale),
                                 path.PoseAt(1));
  pair->length = (path.keyframes.front().centre_in_world - path.keyframes.back().centre_in_world).norm();
  const Eigen::Vector3d& a = plan.starts[pair->a].framing.centre_in_world;
  const Eigen::Vector3d& b = plan.ends[pair->b].framing.centre_in_world;
  const auto share = [&](const std::optional<Framing>& pulled, const Eigen::Vector3d& from) {
    return pulled ? 100 * (pulled->centre_in_world - from).norm() / std::max(1e-9, (a - b).norm()) : 0.0;
  };
  char text[160];
  std::snprintf(text,
                sizeof(text),
                "ends pulled back to hold at the verify size: start %.0f%%, end %.0f%% of the path",
                share(pair->start_pulled, a),
                share(pair->end_pulled, b));
  path.notes.push_back(text);
}

// Whether every frame of the pair's path is valid at the verify size, its ends pulled back where
// they must be; its largest H(V) goes to `max_hole_score`, and why it fails to `last_failure`.
StatusOr<bool> VerifyPath(MovePlan* plan, Pair* pair) {
  ++plan->report->paths_verified;
  PX_ASSIGN_OR_RETURN(bool ends_hold, HoldEnds(*plan, pair));
  if (!ends_hold) {
    plan->last_failure = "an end does not hold at the verify size, pulled back by up to " +
                         std::to_string(static_cast<int>(100 * kMaxPullBack)) + "% of the path";
    return false;
  }
  if (pair->start_pulled || pair->end_pulled) MeasurePulledPath(*plan, pair);
  const PlanContext& context = plan->context;
  PX_ASSIGN_OR_RETURN(
      double worst,
      WorstHoleScore(pair->path, plan->options.search.verify_frames, context.verify, pair->ends_score, context.search));
  if (worst >= context.verify->valid_hole_score()) {
    char text[160];
    std::snprintf(text, sizeof(text), "a frame of the path has H(V) %.2f at the verify size", worst);
    plan->last_failure = text;
    return false;
  }
  pair->max_hole_score = worst;
  return true;
}

// The end framing a subject close up carries the full aperture of a depth-of-field change.
bool SubjectAtStart(Move move) { return move == Move::kDollyOut || move == Move::kDollyZoomIn; }

// The keys whose aperture must hold: a focus pull holds the aperture at both ends, a
// depth-of-field change opens from a pinhole (already verified) to the full aperture at the
// subject's end, the only end it constrains.
std::vector<size_t> ApertureKeys(Move move, Effect effect, size_t last) {
  return effect == Effect::kFocusPull ? std::vector<size_t>{0, last}
                                      : std::vector<size_t>{SubjectAtStart(move) ? 0 : last};
}

// The aperture of a depth-of-field effect, the largest the path's ends hold (0 for any other
// effect). False when the effect needs one its ends cannot hold (an end on the valid region's
// frontier), which sends the search on to the next path; why goes to `last_failure`.
StatusOr<bool> FindEffectAperture(MovePlan* plan, const Pair& pair, double* aperture) {
  const Effect effect = plan->choice.effect;
  *aperture = 0;
  if (effect != Effect::kDofChange && effect != Effect::kFocusPull) return true;
  PX_ASSIGN_OR_RETURN(
      *aperture,
      PathAperture(pair.path, ApertureKeys(plan->choice.move, effect, pair.path.keyframes.size() - 1), plan->context));
  if (*aperture >= 1e-4) return true;
  plan->last_failure = std::string(EffectName(effect)) + ": no aperture of 0.1 mm or more keeps " +
                       (effect == Effect::kFocusPull ? "both ends" : "the subject's end") + " valid";
  return false;
}

// The effect on the path's keys: a depth-of-field effect's aperture and focus (`aperture`: the
// largest valid), or a colour-effect layer on the first subject growing along the path.
void ApplyEffect(const MovePlan& plan, Effect effect, double aperture, CameraPath* path) {
  const Subject* first = plan.first;
  const Subject* second = plan.second;
  if (effect == Effect::kDofChange || effect == Effect::kFocusPull) {
    const bool subject_at_start = SubjectAtStart(plan.choice.move);
    for (size_t k = 0; k < path->keyframes.size(); ++k) {
      CameraKeyframe& key = path->keyframes[k];
      const double t = key.t;
      if (effect == Effect::kFocusPull) {
        key.aperture_m = aperture;
        key.focus_depth_m = SubjectDepthIn(t < 0.5 ? *first : *second, key.CamFromWorld());
      } else {
        key.aperture_m = aperture * (subject_at_start ? 1.0 - t : t);
        key.focus_depth_m = SubjectDepthIn(second != nullptr ? *second : *first, key.CamFromWorld());
      }
    }
    if (effect == Effect::kFocusPull) {
      path->keyframes.front().focus_depth_m = SubjectDepthIn(*first, path->keyframes.front().CamFromWorld());
      path->keyframes.back().focus_depth_m = SubjectDepthIn(*second, path->keyframes.back().CamFromWorld());
    }
  } else if (effect != Effect::kNone && first != nullptr) {
    for (CameraKeyframe& key : path->keyframes) {
      key.effects = {SubjectLayer(*first, effect, 1.0 + key.t * (EffectTarget(effect) - 1.0))};
    }
  }
}

// Why the path was chosen, in words: where it goes, the valid cells, its parallax and H(V).
std::string DescribePath(const MovePlan& plan, const Pair& pair) {
  const CameraPath& path = pair.path;
  const MovePlanReport& report = *plan.report;
  const char* look = plan.along_axis ? "looking along the axis at" : "aimed at";
  // How much the ends enlarge the capture's detail where they are composed, as the region search
  // found them (which holds them to search.max_enlargement); the path's framing may narrow an
  // end's focal to keep the subjects in frame, or set the two-subject dolly's end to the size
  // the first subject started at.
  const double enlargement = std::max(AimEnlargement(plan.scene, StartFraming(plan, pair)),
                                      AimEnlargement(plan.scene, EndFraming(plan, pair)));
  char text[576];
  std::snprintf(
      text,
      sizeof(text),
      "%s from %s %s %s to %s %s %s (%.0f mm); %d/%d valid cells; parallax %.2f%% "
      "(best of %d longest of %d paths); H(V) <= %.2f over %d frames; detail enlarged up to %.2fx at the searched ends",
      plan.name.c_str(),
      Mm(plan.scene.RigFromWorld(path.keyframes.front().centre_in_world)).c_str(),
      look,
      (plan.reverse ? plan.end_what : plan.start_what).c_str(),
      Mm(plan.scene.RigFromWorld(path.keyframes.back().centre_in_world)).c_str(),
      look,
      (plan.reverse ? plan.start_what : plan.end_what).c_str(),
      1000 * pair.length,
      report.valid_cells_start,
      plan.start_region.cells,
      100 * pair.parallax,
      report.paths_measured,
      report.candidate_paths,
      pair.max_hole_score,
      plan.options.search.verify_frames,
      enlargement);
  return text;
}

// The chosen path with its effect (`aperture`: a depth-of-field effect's, the largest valid), its
// figures recorded in the report and its notes and reason written.
StatusOr<CameraPath> CompletePath(MovePlan* plan, Pair* pair, Effect effect, double aperture) {
  MovePlanReport* report = plan->report;
  CameraPath& path = pair->path;
  report->parallax = pair->parallax;
  report->length_m = pair->length;
  report->max_hole_score = pair->max_hole_score;
  report->focal_scale = pair->focal_scale;
  report->aperture_m = aperture;
  ApplyEffect(*plan, effect, aperture, &path);
  path.effect = std::string(EffectName(effect));
  if (report->focal_scale < 0.999) {
    char text[160];
    std::snprintf(text,
                  sizeof(text),
                  "framing narrowed the zoom to %.0f%% to keep every subject wholly in frame",
                  100 * report->focal_scale);
    path.notes.push_back(text);
  }
  for (const Subject* s : {plan->first, plan->second}) {
    if (s != nullptr) path.subjects.push_back(*s);
  }
  path.reason = DescribePath(*plan, *pair);
  PX_RETURN_IF_ERROR(path.Validate());
  return path;
}

}  // namespace

StatusOr<CameraPath> PlanMove(const MoveChoice& choice, const PlanContext& context, MovePlanReport* report) {
  MovePlanReport ignored;
  if (report == nullptr) report = &ignored;
  *report = MovePlanReport{};
  MovePlan plan(choice, context, report);
  PX_RETURN_IF_ERROR(ChooseSubjects(&plan));
  ChooseEndRules(&plan);
  FitRulesToSubjects(&plan);

  // 1-2. Valid regions (shared with earlier moves that framed the same) and candidate endpoints.
  PX_RETURN_IF_ERROR(FindStarts(&plan));
  if (plan.dolly_zoom) {
    PX_RETURN_IF_ERROR(MoveDollyZoomStartBack(&plan));
    plan.end_rule = DollyZoomEndRule(plan);
  }
  PX_RETURN_IF_ERROR(FindEnds(&plan));

  // 3. Candidate pairs, longest first. Framing (where each end looks, its focal, the subjects kept
  //    wholly in frame) costs no coverage probe, so it is checked first: the `num_longest` longest
  //    pairs that keep their subjects in frame have their parallax measured.
  PX_RETURN_IF_ERROR(ListCandidatePairs(&plan));
  plan.excluded_starts.assign(plan.starts.size(), 0);
  plan.excluded_ends.assign(plan.ends.size(), 0);

  // 4. The first (most parallax) path of the batch whose frames are all valid; where none is,
  //    the next batch, without the ends the failed one's paths mostly shared.
  // 5. The image effect. An aperture the path's ends cannot hold (an end on the valid region's
  //    frontier) sends the search on to the next path; the first path that held is kept, without
  //    the effect, in case none can.
  Pair* without_effect = nullptr;
  for (int batch = 0; batch < context.path_batches && without_effect == nullptr; ++batch) {
    if (batch > 0) ExcludeEndsOfFailedBatch(&plan);
    KeepFramedPairs(&plan, /*screen=*/batch > 0);
    if (plan.measured.empty()) break;
    if (batch < context.first_batch) continue;  // tried by an earlier call: its exclusions only
    MeasureParallax(&plan);
    plan.report->paths_measured += static_cast<int>(plan.measured.size());
    for (Pair& pair : plan.measured) {
      PX_ASSIGN_OR_RETURN(bool holds, VerifyPath(&plan, &pair));
      if (!holds) continue;
      double aperture = 0;
      PX_ASSIGN_OR_RETURN(bool effect_holds, FindEffectAperture(&plan, pair, &aperture));
      if (effect_holds) return CompletePath(&plan, &pair, choice.effect, aperture);
      if (without_effect == nullptr) without_effect = &pair;
    }
  }
  if (without_effect != nullptr) {
    without_effect->path.notes.push_back(
        std::string(EffectName(choice.effect)) + " dropped: no aperture of 0.1 mm or more keeps " +
        (choice.effect == Effect::kFocusPull ? "both ends" : "the subject's end") + " of any path that holds valid");
    return CompletePath(&plan, without_effect, Effect::kNone, 0.0);
  }
  return FailedPreconditionError(plan.name + ": none of the " + std::to_string(plan.pairs.size()) +
                                 " candidate paths holds (" + std::to_string(plan.report->paths_measured) +
                                 " kept their subjects in frame and were tried; last: " + plan.last_failure + ")");
}

}  // namespace px::direct
