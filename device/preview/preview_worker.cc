#include "device/preview/preview_worker.h"

#include <signal.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <algorithm>
#include <iostream>
#include <limits>
#include <numeric>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "capture/recording.h"
#include "device/clip_job.h"
#include "device/config.h"
#include "device/daemon_factory.h"
#include "device/preview/preview_protocol.h"
#include "device/worker/write_all.h"
#include "pipeline/core/log.h"
#include "pipeline/core/stage_clock.h"
#include "pipeline/direct/coverage_probe.h"
#include "pipeline/direct/detail_size.h"
#include "pipeline/direct/scene_geometry.h"
#include "pipeline/render/gl/web_scene.h"

namespace px::device {

namespace {

constexpr int kPreviewJpegQuality = 80;
constexpr double kDraftScale = 2;  // a draft frame is drawn at 1 / kDraftScale of the preview's size

// A frame's camera: K, and cam_from_world as a row-major rotation and a translation.
nlohmann::json CameraJson(const VirtualCamera& camera) {
  const Eigen::Matrix3d r = camera.cam_from_world.RotationMatrix();
  const Eigen::Vector3d& t = camera.cam_from_world.translation;
  nlohmann::json rotation = nlohmann::json::array();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) rotation.push_back(r(i, j));
  }
  return {{"width", camera.camera.width},
          {"height", camera.camera.height},
          {"fx", camera.camera.fx},
          {"fy", camera.camera.fy},
          {"cx", camera.camera.cx},
          {"cy", camera.camera.cy},
          {"rotation", rotation},
          {"translation", {t.x(), t.y(), t.z()}}};
}

// False when the daemon is gone (PR_SET_PDEATHSIG then ends us).
bool SendBytes(const char* data, size_t size) { return WriteAll(kPreviewMessageFd, std::string_view(data, size)) == 0; }

bool SendLine(const nlohmann::json& reply) {
  const std::string line = reply.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  return SendBytes(line.data(), line.size());
}

// The scene and the renderer a session draws with.
struct PreviewScene {
  PipelineScene scene;
  std::unique_ptr<render::gl::BackendSceneRenderer> renderer;
  double focal_px = 0;          // the views' mean horizontal focal length: a keyframe's focal_scale is relative to it
  double valid_hole_score = 2;  // H(V) below which the planner calls a viewpoint valid
  double search_scale = 0.125;  // the size, against the clip's, at which the planner searches H(V)
  double grid_extent = 2;       // the planner's grid side against the views' bounding box
  RenderOptions render;         // the pipeline's, for the scene a browser's renderer is sent
};

StatusOr<PreviewScene> LoadScene(const nlohmann::json& request) {
  if (!request.is_object() || !request.contains("capture_dir") || !request["capture_dir"].is_string()) {
    return InvalidArgumentError("preview: the first request names capture_dir");
  }
  PX_ASSIGN_OR_RETURN(DaemonConfig config, DaemonConfigFromJson(request.value("config", nlohmann::json::object())));
  PX_RETURN_IF_ERROR(SetLogLevels(config.log_levels));
  PX_ASSIGN_OR_RETURN(ClipJobOptions options, ClipJobOptionsFromConfig(config));
  const std::filesystem::path capture_dir = request["capture_dir"].get<std::string>();
  PX_ASSIGN_OR_RETURN(Recording recording, ReadRecording(capture_dir));
  PipelineOptions pipeline = options.pipeline;
  const RigCalibration rig = RigCalibrationFor(recording, capture_dir, &pipeline);
  PreviewScene preview;
  preview.valid_hole_score = pipeline.direct.search.valid_hole_score;
  preview.search_scale = pipeline.direct.search.search_scale;
  preview.grid_extent = pipeline.direct.search.grid_extent;
  preview.render = pipeline.render;
  PX_ASSIGN_OR_RETURN(preview.scene, BuildPipelineScene(recording.frames, rig, pipeline));
  PX_ASSIGN_OR_RETURN(preview.renderer,
                      render::gl::BackendSceneRenderer::Create(
                          preview.scene.views, preview.scene.layers, pipeline.render, pipeline.render_backend));
  for (const View& view : preview.scene.views) preview.focal_px += view.camera.fx / preview.scene.views.size();
  return preview;
}

nlohmann::json SceneSummary(const PreviewScene& preview, double ms) {
  nlohmann::json views = nlohmann::json::array();
  double min_depth = 0;
  double max_depth = 0;
  for (const View& view : preview.scene.views) {
    const Eigen::Vector3d centre = view.cam_from_world.Inverse().translation;
    views.push_back({{"id", view.id.value},
                     {"centre_m", {centre.x(), centre.y(), centre.z()}},
                     {"width", view.camera.width},
                     {"height", view.camera.height}});
  }
  for (const DepthMap& map : preview.scene.depth_maps) {
    double lo = 0;
    double hi = 0;
    cv::minMaxLoc(map.depth_m, &lo, &hi, nullptr, nullptr, map.depth_m > 0);
    if (lo > 0 && (min_depth == 0 || lo < min_depth)) min_depth = lo;
    max_depth = std::max(max_depth, hi);
  }
  return {{"views", views},
          {"focal_px", preview.focal_px},
          {"depth_min_m", min_depth},
          {"depth_max_m", max_depth},
          {"render_backend", std::string(preview.renderer->BackendName())},
          {"warnings", preview.scene.report.warnings},
          {"ms", ms}};
}

Status ServeFrame(PreviewScene& preview, const nlohmann::json& request) {
  const auto start = StageClock::now();
  PX_ASSIGN_OR_RETURN(PreviewCamera view, PreviewCameraFromJson(request["frame"], preview.focal_px));
  // Beyond the capture's detail a bigger frame shows nothing more: drawn at that detail, enlarged.
  // A draft (a frame of a drag, replaced when the pointer rests) is drawn at half the preview's
  // size at most: a quarter of the work, so the picture keeps up with the pointer.
  const double draw_scale = std::max(view.output_scale, request.value("draft", false) ? kDraftScale : 1.0);
  const VirtualCamera drawn = direct::CameraAtDetail(view.camera, draw_scale);
  PX_ASSIGN_OR_RETURN(FrameRender frame, preview.renderer->Render(drawn));
  const cv::Mat bgr = direct::EnlargeToOutput(frame.bgr, view.camera.camera.width, view.camera.camera.height);
  // Lossless: for comparing the frame with another renderer's (tests/browser/web_scene_bench.py).
  const bool lossless = request.value("lossless", false);
  std::vector<uchar> image;
  if (!(lossless ? cv::imencode(".png", bgr, image)
                 : cv::imencode(".jpg", bgr, image, {cv::IMWRITE_JPEG_QUALITY, kPreviewJpegQuality}))) {
    return InternalError("preview: image encoding failed");
  }
  nlohmann::json reply = {{"ok", true},
                          {"bytes", image.size()},
                          {"drawn", {drawn.camera.width, drawn.camera.height}},
                          {"camera", CameraJson(drawn)},
                          {"hole_ratio", frame.holes.hole_ratio}};
  if (request.value("coverage", false)) {
    // H(V) exactly as the path planner judges a viewpoint (its verify probe).
    const CoverageFunction coverage = [&preview](const CameraModel& camera, const Rigid3& cam_from_world) {
      return preview.renderer->Coverage(camera, cam_from_world);
    };
    direct::CoverageProbe probe(&coverage, view.verify_scale, preview.valid_hole_score);
    PX_ASSIGN_OR_RETURN(const double h_v, probe.HoleScore(view.clip_camera.camera, view.clip_camera.cam_from_world));
    reply["h_v"] = h_v;
    reply["valid"] = h_v < preview.valid_hole_score;
  }
  reply["render_ms"] = MsSince(start);
  SendLine(reply);
  SendBytes(reinterpret_cast<const char*>(image.data()), image.size());
  return OkStatus();
}

// The scene as a renderer in the browser draws it: what the GL back end would upload.
Status ServeSceneExport(PreviewScene& preview, const RenderOptions& render) {
  const auto start = StageClock::now();
  std::vector<render::gl::PosedLayeredView> posed;
  for (size_t v = 0; v < preview.scene.views.size(); ++v) {
    posed.push_back({preview.scene.layers[v], preview.scene.views[v].cam_from_world});
  }
  PX_ASSIGN_OR_RETURN(const std::string scene, render::gl::ExportWebScene(posed, render::gl::GlOptionsFrom(render)));
  SendLine({{"ok", true}, {"bytes", scene.size()}, {"ms", MsSince(start)}});
  SendBytes(scene.data(), scene.size());
  return OkStatus();
}

// The scene point under pixel (x, y) of the viewpoint: what a click on the preview focuses on.
Status ServeProbe(PreviewScene& preview, const nlohmann::json& request) {
  PX_ASSIGN_OR_RETURN(PreviewCamera view, PreviewCameraFromJson(request["probe"], preview.focal_px));
  const VirtualCamera& camera = view.camera;
  if (!request.contains("x") || !request.contains("y") || !request["x"].is_number() || !request["y"].is_number()) {
    return InvalidArgumentError("probe: x and y (preview pixels) are required");
  }
  const int x = request["x"].get<int>();
  const int y = request["y"].get<int>();
  if (x < 0 || y < 0 || x >= camera.camera.width || y >= camera.camera.height) {
    return OutOfRangeError("probe: pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                           ") is outside the preview");
  }
  PX_ASSIGN_OR_RETURN(FrameRender frame, preview.renderer->Render(camera));
  const double depth = frame.depth_m.at<float>(y, x);
  if (!(depth > 0)) return NotFoundError("probe: no scene depth at that pixel");
  const Eigen::Vector3d in_camera(
      (x - camera.camera.cx) / camera.camera.fx * depth, (y - camera.camera.cy) / camera.camera.fy * depth, depth);
  const Eigen::Vector3d in_world = camera.cam_from_world.Inverse() * in_camera;
  SendLine({{"ok", true}, {"point_m", {in_world.x(), in_world.y(), in_world.z()}}, {"depth_m", depth}});
  return OkStatus();
}

// What a rectangle drawn on the preview covers in the scene: its points' 3D box (trimmed of the
// outer 5 % on each axis: a stray background pixel must not stretch it) for a colour effect's
// region, and its box in the centre view's pixels, for a taxonomy move's subject.
Status ServeRegion(PreviewScene& preview, const nlohmann::json& request) {
  PX_ASSIGN_OR_RETURN(PreviewCamera view, PreviewCameraFromJson(request["region"], preview.focal_px));
  const nlohmann::json& rect = request.value("rect", nlohmann::json());
  if (!rect.is_array() || rect.size() != 4 ||
      !std::all_of(rect.begin(), rect.end(), [](auto& v) { return v.is_number(); })) {
    return InvalidArgumentError("region: rect [x, y, w, h] in preview pixels is required");
  }
  const cv::Rect2d wanted(rect[0].get<double>(), rect[1].get<double>(), rect[2].get<double>(), rect[3].get<double>());
  const cv::Rect2d frame_rect(0, 0, view.camera.camera.width, view.camera.camera.height);
  const cv::Rect2d area = wanted & frame_rect;
  if (area.width < 2 || area.height < 2)
    return OutOfRangeError("region: the rectangle is outside the preview or too small");
  PX_ASSIGN_OR_RETURN(FrameRender frame, preview.renderer->Render(view.camera));
  const Rigid3 world_from_cam = view.camera.cam_from_world.Inverse();
  std::vector<Eigen::Vector3d> points;
  constexpr int kSamples = 24;  // per side
  for (int i = 0; i < kSamples; ++i) {
    for (int j = 0; j < kSamples; ++j) {
      const int x = static_cast<int>(area.x + (j + 0.5) * area.width / kSamples);
      const int y = static_cast<int>(area.y + (i + 0.5) * area.height / kSamples);
      const double depth = frame.depth_m.at<float>(y, x);
      if (!(depth > 0)) continue;
      const CameraModel& c = view.camera.camera;
      points.push_back(world_from_cam * Eigen::Vector3d((x - c.cx) / c.fx * depth, (y - c.cy) / c.fy * depth, depth));
    }
  }
  if (points.size() < 8) return NotFoundError("region: no scene depth inside the rectangle");
  Eigen::Vector3d low;
  Eigen::Vector3d high;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> values;
    for (const Eigen::Vector3d& p : points) values.push_back(p[axis]);
    std::sort(values.begin(), values.end());
    low[axis] = values[values.size() / 20];
    high[axis] = values[values.size() - 1 - values.size() / 20];
  }
  // The points as the centre view saw them: a taxonomy move's subject box.
  const View& centre = preview.scene.views[direct::CentreViewIndex(preview.scene.views)];
  cv::Rect2d in_view;
  bool any = false;
  for (const Eigen::Vector3d& p : points) {
    Eigen::Vector2d pixel;
    if (!centre.camera.Project(centre.cam_from_world * p, &pixel)) continue;
    const cv::Rect2d dot(pixel.x(), pixel.y(), 0, 0);
    in_view = any ? (in_view | dot) : dot;
    any = true;
  }
  in_view &= cv::Rect2d(0, 0, centre.camera.width, centre.camera.height);
  nlohmann::json reply = {{"ok", true},
                          {"region_min_m", {low.x(), low.y(), low.z()}},
                          {"region_max_m", {high.x(), high.y(), high.z()}},
                          {"points", points.size()}};
  if (any && in_view.width >= 1 && in_view.height >= 1) {
    reply["view"] = centre.id.value;
    reply["box_px"] = {in_view.x, in_view.y, in_view.width, in_view.height};
  }
  SendLine(reply);
  return OkStatus();
}

// H(V) over the plane the camera moves in while dragged (world x, y at its own z; its direction,
// up and focal length kept): a cells x cells grid across grid_extent times the views' bounding
// box (at least 4 cm, and wide enough to hold the camera), each cell probed as the planner's search probes
// (paper 4.2.1), so the page can draw where the camera may go.
Status ServeMap(PreviewScene& preview, const nlohmann::json& request) {
  PX_ASSIGN_OR_RETURN(PreviewCamera view, PreviewCameraFromJson(request["map"], preview.focal_px));
  const int cells = request.value("cells", 12);
  if (cells < 3 || cells > 32) return OutOfRangeError("map: cells " + std::to_string(cells) + " is not in [3, 32]");
  Eigen::Vector2d low(std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity());
  Eigen::Vector2d high = -low;
  for (const View& v : preview.scene.views) {
    const Eigen::Vector3d centre = v.cam_from_world.Inverse().translation;
    low = low.cwiseMin(centre.head<2>());
    high = high.cwiseMax(centre.head<2>());
  }
  const Eigen::Vector2d middle = (low + high) / 2;
  const Rigid3 world_from_cam = view.clip_camera.cam_from_world.Inverse();
  // Wide enough to show the camera itself, a cell beyond it.
  const double reach = (world_from_cam.translation.head<2>() - middle).cwiseAbs().maxCoeff();
  const double side =
      std::max({0.04, preview.grid_extent * (high - low).maxCoeff(), 2 * reach * cells / (cells - 2.0)});
  const double z = world_from_cam.translation.z();
  const CoverageFunction coverage = [&preview](const CameraModel& camera, const Rigid3& cam_from_world) {
    return preview.renderer->Coverage(camera, cam_from_world);
  };
  direct::CoverageProbe probe(&coverage, preview.search_scale, preview.valid_hole_score);
  nlohmann::json xs = nlohmann::json::array(), ys = nlohmann::json::array(), h_v = nlohmann::json::array();
  for (int i = 0; i < cells; ++i) {
    xs.push_back(middle.x() + side * ((i + 0.5) / cells - 0.5));
    ys.push_back(middle.y() + side * ((i + 0.5) / cells - 0.5));
  }
  const auto start = StageClock::now();
  for (int row = 0; row < cells; ++row) {
    nlohmann::json line = nlohmann::json::array();
    for (int column = 0; column < cells; ++column) {
      Rigid3 moved = world_from_cam;
      moved.translation = Eigen::Vector3d(xs[column].get<double>(), ys[row].get<double>(), z);
      PX_ASSIGN_OR_RETURN(const double score, probe.HoleScore(view.clip_camera.camera, moved.Inverse()));
      line.push_back(score);
    }
    h_v.push_back(std::move(line));
  }
  SendLine({{"ok", true},
            {"x_m", xs},
            {"y_m", ys},
            {"z_m", z},
            {"h_v", h_v},
            {"valid_below", preview.valid_hole_score},
            {"ms", MsSince(start)}});
  return OkStatus();
}

}  // namespace

int RunPreviewWorker(pid_t parent) {
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlive the daemon
  if (::getppid() != parent) return 1;
  std::string line;
  if (!std::getline(std::cin, line)) return 1;
  const auto start = StageClock::now();
  nlohmann::json first = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
  StatusOr<PreviewScene> preview = LoadScene(first);
  if (!preview.ok()) {
    SendLine(PreviewErrorReply(preview.status()));
    return 1;
  }
  Logger("device")->info("preview: scene of {} views ready in {:.0f} ms", preview->scene.views.size(), MsSince(start));
  if (!SendLine({{"ok", true}, {"scene", SceneSummary(*preview, MsSince(start))}})) return 1;
  while (std::getline(std::cin, line)) {
    nlohmann::json request = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
    Status served =
        InvalidArgumentError("preview: a request is a JSON object with frame, probe, region, map or scene_export");
    if (request.is_object() && request.contains("frame")) {
      served = ServeFrame(*preview, request);
    } else if (request.is_object() && request.contains("probe")) {
      served = ServeProbe(*preview, request);
    } else if (request.is_object() && request.contains("region")) {
      served = ServeRegion(*preview, request);
    } else if (request.is_object() && request.contains("map")) {
      served = ServeMap(*preview, request);
    } else if (request.is_object() && request.contains("scene_export")) {
      served = ServeSceneExport(*preview, preview->render);
    }
    if (!served.ok() && !SendLine(PreviewErrorReply(served))) return 1;
  }
  return 0;
}

}  // namespace px::device
