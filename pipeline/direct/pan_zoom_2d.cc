#include "pipeline/direct/pan_zoom_2d.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "pipeline/direct/framing.h"

namespace px::direct {

namespace {

// The frame never shows the whole image (it would have no room to move): at least this much
// zoom over the view's own focal length.
constexpr double kMinZoom = 1.04;

struct FlatKey {
  Eigen::Vector3d direction;  // world direction of the optical axis
  double focal_px = 0;
};

Rigid3 Pose(const View& view, const Eigen::Vector3d& direction) {
  const Eigen::Vector3d centre = CameraCentre(view.cam_from_world);
  const Eigen::Vector3d up = view.cam_from_world.rotation.conjugate() * -Eigen::Vector3d::UnitY();
  return Rigid3::LookAt(centre, centre + direction, up);
}

// The clip's frame over the view (output_frame.h): its size and aspect, at a zoom given as a
// focal length in the view's own pixels.
struct FlatFrame {
  CameraModel base;  // the view's widest crop of the output's aspect, at the output's size
  double scale = 1;  // output pixels per view pixel

  CameraModel At(double focal_px) const {
    CameraModel camera = base;
    camera.fy = focal_px * scale * base.fy / base.fx;
    camera.fx = focal_px * scale;
    return camera;
  }
};

Eigen::Vector3d Axis(const View& view) { return view.cam_from_world.rotation.conjugate() * Eigen::Vector3d::UnitZ(); }

// Turns the key towards the view's own axis (and zooms in if needed) until its frame lies inside
// the image: the most of the wanted aim that the image allows.
FlatKey FitInside(const View& view, const FlatFrame& frame, FlatKey key) {
  const double f = view.camera.fx;
  key.focal_px = std::max(key.focal_px, kMinZoom * f);
  const auto inside = [&](const Eigen::Vector3d& direction) {
    return FrameInsideSource(view, frame.At(key.focal_px), Pose(view, direction));
  };
  if (inside(key.direction)) return key;
  const Eigen::Vector3d axis = Axis(view);
  const Eigen::Vector3d wanted = key.direction.normalized();
  double lo = 0, hi = 1;
  for (int i = 0; i < 30; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (inside(((1 - mid) * axis + mid * wanted).normalized())) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  key.direction = ((1 - lo) * axis + lo * wanted).normalized();
  return key;
}

FlatKey Towards(const View& view, const Eigen::Vector3d& point_in_world, double focal_px) {
  return {(point_in_world - CameraCentre(view.cam_from_world)).normalized(), focal_px};
}

}  // namespace

cv::Matx33d FlatFrameHomography(const View& source, const CameraModel& camera, const Rigid3& cam_from_world) {
  const Eigen::Matrix3d h = camera.K() * cam_from_world.RotationMatrix() *
                            source.cam_from_world.RotationMatrix().transpose() *
                            source.camera.WithoutDistortion().K().inverse();
  cv::Matx33d out;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out(r, c) = h(r, c);
  }
  return out;
}

bool FrameInsideSource(const View& source, const CameraModel& camera, const Rigid3& cam_from_world) {
  const Eigen::Matrix3d source_from_frame = source.camera.WithoutDistortion().K() *
                                            source.cam_from_world.RotationMatrix() *
                                            cam_from_world.RotationMatrix().transpose() * camera.K().inverse();
  const double w = camera.width, h = camera.height;
  for (const Eigen::Vector2d& corner : {Eigen::Vector2d(-0.5, -0.5),
                                        Eigen::Vector2d(w - 0.5, -0.5),
                                        Eigen::Vector2d(w - 0.5, h - 0.5),
                                        Eigen::Vector2d(-0.5, h - 0.5)}) {
    const Eigen::Vector3d p = source_from_frame * Eigen::Vector3d(corner.x(), corner.y(), 1.0);
    if (!(p.z() > 1e-9)) return false;
    const double x = p.x() / p.z(), y = p.y() / p.z();
    if (x < -0.5 - 1e-6 || y < -0.5 - 1e-6 || x > source.camera.width - 0.5 + 1e-6 ||
        y > source.camera.height - 0.5 + 1e-6) {
      return false;
    }
  }
  return true;
}

StatusOr<CameraPath> PlanPanZoom2d(const View& view,
                                   const std::vector<Subject>& subjects,
                                   const DirectOptions& options) {
  PX_RETURN_IF_ERROR(view.camera.Validate().WithContext("pan and zoom: view " + std::to_string(view.id.value)));
  std::mt19937_64 rng(options.seed);
  const bool reverse = rng() % 2 == 1;
  const double f = view.camera.fx;
  const double zoomed = options.zoom_in * f;
  const Eigen::Vector3d centre = CameraCentre(view.cam_from_world);
  const Eigen::Vector3d axis = Axis(view);
  const CameraModel pinhole = view.camera.WithoutDistortion();
  FlatFrame frame;
  frame.base = FrameOutputCamera(
      pinhole, ResolveOutputSize(options.output, view.camera.width, view.camera.height), &frame.scale);
  const Rigid3 world_from_cam = view.cam_from_world.Inverse();

  FlatKey a, b;
  std::string move;
  if (subjects.empty()) {
    // Slow zoom out from one side towards the whole view.
    const double side = (rng() % 2 == 0 ? -0.12 : 0.12) * view.camera.width;
    const Eigen::Vector3d off = world_from_cam.rotation * pinhole.Unproject({pinhole.cx + side, pinhole.cy});
    a = {off.normalized(), 1.35 * f};
    b = {axis, 1.06 * f};
    move = "pan_zoom_out";
  } else if (subjects.size() == 1) {
    a = {axis, 1.06 * f};
    b = Towards(view, subjects[0].LowerHalfCentreInWorld(), zoomed);
    move = "pan_zoom_in";
  } else {
    const Subject& s1 = subjects[0];
    const Subject& s2 = subjects[1];
    a = Towards(view, s1.LowerHalfCentreInWorld(), zoomed);
    b = Towards(view, s2.LowerHalfCentreInWorld(), zoomed * s1.box_px.height / std::max(1.0, s2.box_px.height));
    move = "pan_between_subjects";
  }
  if (reverse) std::swap(a, b);

  // Subjects first: narrow each key's zoom until they fit (never below kMinZoom), then keep the
  // frame inside the image.
  const double margin_px = options.framing_margin * frame.base.width;
  std::vector<FlatKey> keys = {a, b};
  Eigen::Vector3d towards_subjects = Eigen::Vector3d::Zero();
  for (const Subject& subject : subjects)
    towards_subjects += Towards(view, subject.LowerHalfCentreInWorld(), f).direction;
  for (FlatKey& key : keys) {
    // A frame narrower than the view (a portrait cut from a landscape) can miss the subjects from
    // the key's aim at any zoom: turn it towards them, as little as brings them into frame.
    const auto framed = [&](const Eigen::Vector3d& direction) {
      return SubjectsInside(subjects, frame.At(kMinZoom * f), Pose(view, direction), margin_px);
    };
    if (!subjects.empty() && !framed(key.direction)) {
      const Eigen::Vector3d from = key.direction.normalized();
      const Eigen::Vector3d to = towards_subjects.normalized();
      double lo = 0, hi = 1;
      for (int i = 0; i < 30; ++i) {
        const double mid = 0.5 * (lo + hi);
        (framed(((1 - mid) * from + mid * to).normalized()) ? hi : lo) = mid;
      }
      key.direction = ((1 - hi) * from + hi * to).normalized();
    }
    const double most =
        MaxFocalKeepingInside(subjects, frame.At(key.focal_px), Pose(view, key.direction), margin_px) / frame.scale;
    key.focal_px = std::max(kMinZoom * f, std::min(key.focal_px, most));
    key = FitInside(view, frame, key);
  }

  CameraPath path = BlankPath(PathKind::kPanZoom2d, move, frame.base, options.fps, options.duration_s);
  path.output_scale = frame.scale;
  path.source_views = {view.id.value};
  path.subjects = subjects;
  for (size_t i = 0; i < keys.size(); ++i) {
    CameraKeyframe key;
    key.t = static_cast<double>(i);
    key.centre_in_world = centre;
    key.cam_from_world_rotation = Pose(view, keys[i].direction).rotation;
    key.focal_px = keys[i].focal_px * frame.scale;
    path.keyframes.push_back(key);
  }
  // Between the keys the frame turns and zooms linearly; nudge the zoom up until every frame is
  // inside the image.
  for (int round = 0; round < 20; ++round) {
    bool all_inside = true;
    for (int i = 0; i < path.NumFrames() && all_inside; ++i) {
      const double t = path.FrameTime(i);
      all_inside = FrameInsideSource(view, path.CameraAt(t), path.PoseAt(t));
    }
    if (all_inside) break;
    for (CameraKeyframe& key : path.keyframes) key.focal_px *= 1.02;
  }
  int frames_cut = 0;
  for (int i = 0; i < path.NumFrames(); ++i) {
    const double t = path.FrameTime(i);
    frames_cut += SubjectsInside(subjects, path.CameraAt(t), path.PoseAt(t), 0) ? 0 : 1;
  }
  if (frames_cut > 0) {
    path.notes.push_back("the view is too tight to keep every subject wholly in " + std::to_string(frames_cut) +
                         " of " + std::to_string(path.NumFrames()) + " frames");
  }
  char reason[200];
  std::snprintf(reason,
                sizeof(reason),
                "flat %s over view %d (%zu subject%s), zoom %.2ff to %.2ff",
                move.c_str(),
                view.id.value,
                subjects.size(),
                subjects.size() == 1 ? "" : "s",
                path.keyframes[0].focal_px / (frame.scale * f),
                path.keyframes[1].focal_px / (frame.scale * f));
  path.reason = reason;
  PX_RETURN_IF_ERROR(path.Validate());
  return path;
}

}  // namespace px::direct
